//! Two-plane rotors (files written by ROSS `Rotor.save`): damped modes at one speed, bearing
//! stiffnesses from run-up frequencies, and the Campbell diagram.

use crate::error::{input, WorkflowError};
use crate::named::Named;
use crate::outcome::SearchReport;
use crate::outcome::{
    phase_counts, AlternativeSolution, BudgetReport, Covariances, FitQualityReport, Outcome,
    ParameterIdentifiability, ParameterValues, Verdict,
};
use eigenfit_core::analysis::alternatives::{
    adopt_better_minimum, better_minimum, like_exchanges, listed_alternatives, mirror_solutions,
    screened_fits, screened_local_minima, screened_search, Equivalence, Mirrors, Screening,
};
use eigenfit_core::analysis::verdict::{at_limits, judge};
use eigenfit_core::analysis::{uncertainty_parallel, Identifiability};
use eigenfit_core::update::refit::Damped;
use eigenfit_core::update::Budget;
use eigenfit_rotordynamics::campbell::refine_critical_speed;
use eigenfit_rotordynamics::fit::fit_runup;
use eigenfit_rotordynamics::identify::{
    bearing_parameters, check_selection, evaluate, read_runup, RunupPoint, DEFAULT_COEFFICIENTS,
};
use eigenfit_rotordynamics::interpolation::Coefficient;
use eigenfit_rotordynamics::objective::RunupObjective;
use eigenfit_rotordynamics::shapes::RotorShapes;
use eigenfit_rotordynamics::{campbell, ross_file, rpm_to_rad, Campbell, Rotor, RotorDynError};
use serde::Serialize;
use std::path::Path;

/// The model file if it is a ROSS rotor (judged by its content: tables `ShaftElement_…`).
pub fn ross_model(path: Option<&Path>) -> Option<&Path> {
    let path = path?;
    // A FIFO or device is not read here (it would block): the model loader refuses it.
    crate::model::check_model_file(path).ok()?;
    let text = std::fs::read_to_string(path).ok()?;
    ross_file::looks_like_ross(&text).then_some(path)
}

fn to_workflow(e: RotorDynError) -> WorkflowError {
    match e {
        RotorDynError::Solver(m) => WorkflowError::Failure(m),
        other => input(other.to_string()),
    }
}

/// A ROSS rotor file's text in the format ROSS reads for `path` (JSON for `.json`, TOML
/// otherwise).
pub fn ross_text_for(text: &str, path: &Path) -> Result<String, WorkflowError> {
    ross_file::in_format_for(text, path).map_err(|e| input(format!("{}: {e}", path.display())))
}

/// Refuses, naming what it is, a model file of another kind where `command` needs a ROSS rotor:
/// a planar rotor or a matrices model is said to be one (rather than failing on its first
/// table as "not a ROSS element"). Unreadable files are left to the reader, whose errors name
/// them.
pub fn require_ross(path: &Path, command: &str) -> Result<(), WorkflowError> {
    crate::model::check_model_file(path)?;
    let Ok(text) = std::fs::read_to_string(path) else { return Ok(()) };
    if ross_file::looks_like_ross(&text) {
        return Ok(());
    }
    let what = if eigenfit_matrices::is_matrices_file(&text) {
        "a `kind = \"matrices\"` model (K(p), M(p) from matrix files), which has no rotor speed".to_string()
    } else if eigenfit_rotor::RotorSpec::from_toml_str(&text).is_ok() {
        "a planar rotor model (docs/rotor-model.md), which has no speed-dependent terms: its natural \
         frequencies against support stiffness are `eigenfit simulate --sweep FROM:TO:COUNT`"
            .to_string()
    } else {
        "a file without the `ShaftElement_…` tables of a ROSS rotor".to_string()
    };
    Err(input(format!(
        "{}: {command} needs a two-plane rotor saved by ROSS (`Rotor.save`, docs/rotordynamics.md); \
         this is {what}",
        path.display()
    )))
}

/// Loads a ROSS rotor, errors naming the file.
pub fn load(path: &Path) -> Result<Rotor, WorkflowError> {
    crate::model::check_model_file(path)?;
    ross_file::read(path).map_err(to_workflow)
}

fn check_speed(flag: &str, rpm: f64) -> Result<(), WorkflowError> {
    eigenfit_rotordynamics::check_speed_rpm(rpm).map_err(|e| input(format!("{flag}: {e}")))
}

/// Damped modes of a two-plane rotor at one speed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpeedReport {
    /// The model file.
    pub model: String,
    /// The speed (rpm).
    pub speed_rpm: f64,
    /// Damped frequencies (Hz).
    pub frequencies_hz: Vec<f64>,
    /// Undamped natural frequencies (Hz).
    pub natural_frequencies_hz: Vec<f64>,
    /// `forward` or `backward`.
    pub whirl: Vec<&'static str>,
    /// Damping ratios.
    pub damping_ratio: Vec<f64>,
    /// Logarithmic decrements.
    pub log_dec: Vec<f64>,
    /// Rigid-body modes below the modes listed, left out of them (a rotor without bearings or
    /// seals: eigenvalues zero to round-off); absent when there are none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rigid_body_modes_left_out: Option<usize>,
    /// The rotor's DOFs.
    #[serde(skip)]
    pub dofs: usize,
    /// Plot files written (`simulate --plot`: the mode shapes and orbits).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Vec<String>>,
    /// What the numbers rest on that a reader should know: bearing tables extrapolated,
    /// unstable modes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The rotor solved (the file's, `--set` applied): what `--plot` draws the shapes of.
    #[serde(skip)]
    pub rotor: Rotor,
}

/// Damping ratio below which a mode is called unstable: an undamped rotor's come out of the
/// eigen-solver within ±1e-13 of 0 (rotor_example: |ζ| ≤ 6.2e-14 at 0 and 5000 rpm).
const UNSTABLE_BELOW: f64 = -1e-9;

/// The names `--set` takes on a ROSS rotor: `<coefficient>_<bearing tag>` for every bearing
/// and seal, the coefficients in ROSS's names (stiffness N/m, damping N·s/m, added mass kg).
pub fn settable_names(rotor: &Rotor) -> Vec<String> {
    rotor.bearings.iter().flat_map(|b| SETTABLE.iter().map(move |c| format!("{c}_{}", b.tag))).collect()
}

/// Bearing coefficients `--set` can set, in ROSS's names and [`Bearing`]'s order (k, c, m).
///
/// [`Bearing`]: eigenfit_rotordynamics::elements::Bearing
const SETTABLE: [&str; 12] =
    ["kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy", "mxx", "mxy", "myx", "myy"];

/// Applies `--set NAME=VALUE` items to a ROSS rotor: the named bearing coefficient becomes VALUE at
/// every speed and whirl frequency (its table, if any, is replaced). A name that is not one of
/// [`settable_names`] is refused, listing them.
pub fn apply_sets(rotor: &mut Rotor, sets: &[String]) -> Result<Vec<String>, WorkflowError> {
    let mut notes = Vec::new();
    crate::overrides::refuse_repeated("--set", sets)?;
    for item in sets {
        let (name, value) =
            item.split_once('=').ok_or_else(|| input(format!("--set `{item}`: expected NAME=VALUE")))?;
        let name = name.trim();
        // Two bearings with one tag: the name would set only the first, silently.
        let tagged: Vec<usize> = (0..rotor.bearings.len())
            .filter(|&i| SETTABLE.iter().any(|c| format!("{c}_{}", rotor.bearings[i].tag) == name))
            .collect();
        if tagged.len() > 1 {
            return Err(input(format!(
                "--set {name}: {} bearings share the tag `{}` (at nodes {}); give them distinct tags in the rotor file",
                tagged.len(),
                rotor.bearings[tagged[0]].tag,
                tagged.iter().map(|&i| rotor.bearings[i].n.to_string()).collect::<Vec<_>>().join(", ")
            )));
        }
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| input(format!("--set `{item}`: `{}` is not a finite number", value.trim())))?;
        let hit = rotor.bearings.iter_mut().find_map(|b| {
            let c = SETTABLE.iter().position(|c| format!("{c}_{}", b.tag) == name)?;
            let tag = b.tag.clone();
            let slot = match c {
                0..=3 => &mut b.k[c],
                4..=7 => &mut b.c[c - 4],
                _ => &mut b.m[c - 8],
            };
            let was_table = !matches!(slot, Coefficient::Constant(_));
            *slot = Coefficient::Constant(value);
            Some((tag, was_table))
        });
        match hit {
            Some((tag, true)) => notes.push(format!(
                "--set {name}={value}: the table of {tag}'s {} is replaced by this value at every speed",
                &name[..3]
            )),
            Some(_) => {}
            None => {
                return Err(input(format!(
                    "--set: {}",
                    eigenfit_core::names::unknown("bearing coefficient", name, &settable_names(rotor))
                )))
            }
        }
    }
    Ok(notes)
}

/// `simulate --model ROSS-FILE [--speed RPM] --modes N`: damped modes at one speed.
pub fn simulate(path: &Path, speed_rpm: Option<f64>, modes: usize) -> Result<SpeedReport, WorkflowError> {
    simulate_with(path, speed_rpm, modes, &[])
}

/// [`simulate`] with `--set NAME=VALUE` bearing coefficients (see [`apply_sets`]).
pub fn simulate_with(
    path: &Path,
    speed_rpm: Option<f64>,
    modes: usize,
    sets: &[String],
) -> Result<SpeedReport, WorkflowError> {
    let mut rotor = load(path)?;
    let set_notes = apply_sets(&mut rotor, sets)?;
    let rpm = speed_rpm.unwrap_or(0.0);
    check_speed("--speed", rpm)?;
    if modes == 0 || modes > rotor.dofs() {
        return Err(input(format!("--modes {modes}: must be between 1 and {} for this rotor", rotor.dofs())));
    }
    let all = rotor.lowest_modes(rpm_to_rad(rpm), modes).map_err(to_workflow)?;
    if modes > all.len() {
        return Err(input(format!(
            "--modes {modes}: the rotor has only {} oscillating mode{} at {rpm} rpm, of its {} DOFs (the \
             others are overdamped, rigid-body, or lost to round-off beside an extreme coefficient)",
            all.len(),
            if all.len() == 1 { "" } else { "s" },
            rotor.dofs()
        )));
    }
    let shown = &all[..modes];
    let mut notes = set_notes;
    let rigid = rotor.rigid_body_modes(rpm_to_rad(rpm)).map_err(to_workflow)?;
    notes.extend(rigid_body_note(rigid, rpm));
    notes.extend(divergent_note(&rotor, rpm));
    notes.extend(rotor.extrapolation_notes(&[rpm]));
    notes.extend(rotor.whirl_extrapolation_notes(&shown.iter().map(|m| m.eigenvalue.im).collect::<Vec<_>>()));
    let unstable: Vec<String> = (0..modes)
        .filter(|&i| shown[i].damping_ratio() < UNSTABLE_BELOW)
        .map(|i| (i + 1).to_string())
        .collect();
    if !unstable.is_empty() {
        notes.push(format!(
            "mode(s) {} unstable at {rpm} rpm: negative damping ratio (the vibration grows)",
            unstable.join(", ")
        ));
    }
    Ok(SpeedReport {
        model: path.display().to_string(),
        speed_rpm: rpm,
        frequencies_hz: shown.iter().map(|m| m.frequency_hz()).collect(),
        natural_frequencies_hz: shown.iter().map(|m| m.natural_frequency_hz()).collect(),
        whirl: shown.iter().map(|m| m.whirl.name()).collect(),
        damping_ratio: shown.iter().map(|m| m.damping_ratio()).collect(),
        log_dec: shown.iter().map(|m| m.log_dec()).collect(),
        rigid_body_modes_left_out: (rigid > 0).then_some(rigid),
        dofs: rotor.dofs(),
        plots: None,
        notes,
        rotor,
    })
}

/// Says that the rotor is statically unstable at `rpm` (a growing motion that no mode list
/// holds, [`Rotor::divergent`]).
fn divergent_note(rotor: &Rotor, rpm: f64) -> Option<String> {
    rotor.divergent(rpm_to_rad(rpm)).map(|lambda| {
        format!(
            "the rotor is statically unstable at {rpm} rpm: its stiffness (symmetric part of K) has a \
             negative eigenvalue λ = {lambda:.4e} (rad/s)² — a negative bearing or seal stiffness \
             outweighing the shaft; that motion grows without oscillating, so it is in no mode listed"
        )
    })
}

/// Says that `count` rigid-body modes were left out of the modes listed at `rpm`.
fn rigid_body_note(count: usize, rpm: f64) -> Option<String> {
    (count > 0).then(|| {
        format!(
            "{count} rigid-body mode{} at {rpm} rpm left out of the modes listed (eigenvalues zero to \
             round-off: nothing holds the rotor in {} — no bearing or seal there); they are no \
             vibration and never a critical speed",
            if count == 1 { "" } else { "s" },
            if count == 1 { "that motion" } else { "those motions" }
        )
    })
}

/// One run-up point at the estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupPointReport {
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// Mode number as measured.
    pub mode: usize,
    /// Measured frequency (Hz).
    pub measured_hz: f64,
    /// Model frequency at the estimate (Hz).
    pub model_hz: f64,
    /// Model whirl at the estimate.
    pub model_whirl: &'static str,
    /// Measured whirl, when given.
    pub measured_whirl: Option<&'static str>,
}

/// A run-up point that disagrees with the model by more than 3σ.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupPointId {
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// Mode number as measured.
    pub mode: usize,
}

/// Bearing coefficients of a two-plane rotor from run-up frequencies: the keys of every
/// model kind's estimate (`verdict`, `termination`, `chi2`, `dof`, `p_value`, `acceptable`,
/// `unique`, `parameters`, `intervals`, `identifiable`, `evaluations_by_phase`,
/// `alternative_solutions`), and the run-up's points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupEstimateReport {
    /// The model file.
    pub model: String,
    /// Converged, why it stopped, iterations, eigen-solve rounds.
    #[serde(flatten)]
    pub outcome: Outcome,
    /// The verdict, by the rules of every model kind.
    #[serde(flatten)]
    pub verdict: Verdict,
    /// χ², dof, p-value, relative RMS and the run-up points that miss by more than 3σ.
    #[serde(flatten)]
    pub fit: FitQualityReport<RunupPointId>,
    /// The evaluation budget.
    pub budget: BudgetReport,
    /// Evaluations spent in each phase: fit, mirror_solutions, intervals.
    pub evaluations_by_phase: Named<usize>,
    /// The speed the coefficients are reported at (the lowest measured, rpm).
    pub reference_speed_rpm: f64,
    /// Nominal and estimated coefficients (N/m or N·s/m), each one's interval as text or why
    /// there is none.
    #[serde(flatten)]
    pub values: ParameterValues,
    /// Estimated scale factors on the nominal curves.
    pub scales: Named<f64>,
    /// Each coefficient's unit (N/m for a stiffness, N·s/m for a damping), by name.
    pub units: Named<String>,
    /// The coefficients' covariance (physical coordinates: the coefficients at
    /// `reference_speed_rpm` in their units, from the factors' as the intervals are) and
    /// correlation, `null` when not computed (no std, no convergence) or not computable.
    #[serde(flatten)]
    pub covariances: Covariances,
    /// Σ r² (weighted by std, or of relative residuals without).
    pub cost: f64,
    /// 95 % intervals of the coefficients (profile likelihood where the linearisation is too
    /// wide; `null` without std or when the run did not converge).
    pub intervals: Option<Named<[f64; 2]>>,
    /// Per coefficient: determined by the data (`true`), or `{"identifiable": false}` with the
    /// one bound known on its factor (`null` as `intervals`).
    pub identifiable: Option<Named<ParameterIdentifiability>>,
    /// Restarts from screened other starts taken because the fit from the file's bearings did
    /// not pass (0: it did, or none were allowed).
    pub refits: usize,
    /// Mirror points of a symmetric rotor (exchanged bearings), each with its χ², Δχ² and the
    /// test's outcome.
    pub alternative_solutions: Vec<AlternativeSolution>,
    /// What the search for other solutions did with its starts when each local fit was
    /// budgeted (above 8 coefficients; absent otherwise), as in every model kind's estimate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub search: Option<SearchReport>,
    /// How σ was taken for the alternatives' test: `std`, `residuals` or `exact`.
    pub alternatives_sigma: &'static str,
    /// The run-up points at the estimate.
    pub points: Vec<RunupPointReport>,
    /// Plot files written (`--plot`: the run-up fit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Vec<String>>,
    /// Bearing tables extrapolated at measured speeds.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// With `--write-model`: the input ROSS file, of its version, with the estimated bearing
    /// coefficients (each table multiplied by its estimated factor).
    #[serde(skip)]
    pub updated_model: Option<String>,
    /// The rotor at the estimate: the file's, each estimated coefficient's table multiplied by
    /// its factor (what `--plot` draws at the estimate).
    #[serde(skip)]
    pub estimated_rotor: Rotor,
    /// The fit's iterations (parameters as factors on the file's coefficients), for the
    /// convergence plot.
    #[serde(skip)]
    pub history: Vec<eigenfit_core::update::IterationRecord>,
}

/// Refits from screened other starts a run-up estimate runs at most, when not given.
pub const RUNUP_REFITS: usize = 6;

/// `estimate --model ROSS-FILE --measured RUNUP.csv [--parameters kxx,kyy,…]`: bearing
/// coefficients from a run-up (`selection` `None`: kxx and kyy of every bearing, seals left
/// out), fitted by core's driver on the run-up's objective ([`fit_runup`]: direct stiffnesses
/// first, up to `refits` restarts from screened starts), judged by core's verdict, with core's
/// intervals and mirror solutions, all within `budget` evaluations (one eigen-solve round over
/// the run-up's speeds each).
pub fn estimate(
    path: &Path,
    measured: &Path,
    selection: Option<&str>,
    max_iterations: usize,
    refits: usize,
    budget: usize,
) -> Result<RunupEstimateReport, WorkflowError> {
    let options = RunupOptions { selection, initial: None, write_model: false };
    estimate_with(path, measured, &options, max_iterations, refits, budget)
}

/// What a run-up estimate may be asked beyond the fit's limits.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunupOptions<'a> {
    /// `--parameters`: the coefficients to estimate (default kxx, kyy of every bearing).
    pub selection: Option<&'a str>,
    /// `--initial`: where the fit starts, in the parameters' units at the lowest measured speed —
    /// `V1,V2,…` (one per parameter, in order) or `NAME=VALUE,…` (the others at the file's).
    pub initial: Option<&'a str>,
    /// `--write-model`: build the ROSS file of the input's version with the estimated tables
    /// ([`RunupEstimateReport::updated_model`]).
    pub write_model: bool,
}

/// Options of `estimate` that a run-up fit on a ROSS rotor has no meaning for: the first given is
/// refused before any work, naming it.
pub fn refuse_planar_options(
    strategy: &str,
    residual: &str,
    given: &[(&str, bool)],
) -> Result<(), WorkflowError> {
    if !matches!(strategy, "damped" | "levenberg-marquardt") {
        return Err(input(format!(
            "--strategy {strategy}: a run-up fit on a two-plane (ROSS) rotor is Levenberg–Marquardt (damped) only"
        )));
    }
    if residual != "relative" {
        return Err(input(format!(
            "--residual {residual}: a run-up fit's residual is set by its CSV (in std_hz when given, relative otherwise)"
        )));
    }
    match given.iter().find(|(_, on)| *on) {
        Some((flag, _)) => Err(input(format!(
            "{flag} is not available for two-plane (ROSS) rotors: a run-up fit uses the whirl frequencies of the run-up CSV"
        ))),
        None => Ok(()),
    }
}

/// The starting factors (multiples of the file's coefficients) for `--initial`.
fn initial_factors(
    text: Option<&str>,
    params: &[eigenfit_rotordynamics::identify::Parameter],
    rotor: &Rotor,
    w0: f64,
) -> Result<Vec<f64>, WorkflowError> {
    let mut factors = vec![1.0; params.len()];
    let Some(text) = text else { return Ok(factors) };
    let names = || params.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ");
    let items: Vec<&str> = text.split(',').map(str::trim).filter(|s| !s.is_empty()).collect();
    let mut values: Vec<(usize, f64)> = Vec::new();
    if items.iter().any(|i| i.contains('=')) {
        crate::overrides::refuse_repeated("--initial", &items)?;
        for item in &items {
            let (name, value) = item.split_once('=').ok_or_else(|| {
                input(format!("--initial `{item}`: expected NAME=VALUE like the other items"))
            })?;
            let i = params.iter().position(|p| p.name == name.trim()).ok_or_else(|| {
                let estimated: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
                input(format!(
                    "--initial: {} (the parameters estimated; choose others with --parameters)",
                    eigenfit_core::names::unknown("estimated parameter", name.trim(), &estimated)
                ))
            })?;
            values.push((i, crate::overrides::parse_list("--initial", value)?[0]));
        }
    } else {
        let list = crate::overrides::parse_list("--initial", text)?;
        if list.len() != params.len() {
            return Err(input(format!(
                "--initial: {} values given but {} parameters are estimated ({})",
                list.len(),
                params.len(),
                names()
            )));
        }
        values.extend(list.into_iter().enumerate());
    }
    for (i, v) in values {
        let nominal = params[i].nominal(rotor, w0);
        let factor = v / nominal;
        if !(factor.is_finite() && factor > 0.0) {
            return Err(input(format!(
                "--initial: {}={v} must have the sign of the file's value {nominal:.6e} there (the fit scales \
                 the coefficient's table by a positive factor)",
                params[i].name
            )));
        }
        factors[i] = factor;
    }
    Ok(factors)
}

/// Units a run-up's frequencies are mistyped in, each with the factor that turns its number
/// into Hz (rpm here: cycles per minute).
const RUNUP_UNIT_SLIPS: [(&str, f64); 3] =
    [("kHz", 1e3), ("MHz", 1e6), ("rpm (cycles per minute)", 1.0 / 60.0)];

/// How far (a ratio) every measured frequency must lie from the starting rotor's frequency of
/// its mode number before a unit slip is considered. A bearing factor within 1e-3…1e3 moves a
/// frequency by at most its square root, √1000 ≈ 32 (a mode held by the bearings alone; the
/// shaft's own flexibility holds it closer), so no real run-up lies 40× from the rotor at every
/// point; a slip of kHz (×1e-3) or rpm (×60) does.
const RUNUP_SLIP_RATIO: f64 = 40.0;

/// Refuses a run-up whose frequencies one unit slip explains, as the modal-test paths refuse
/// one: every point lies more than [`RUNUP_SLIP_RATIO`] from the starting rotor's frequency of
/// its mode number at its speed, and converted from one unit ([`RUNUP_UNIT_SLIPS`]) every one
/// lies within a factor of 2 of it. Compared by mode number (the fit pairs by frequency, and
/// would pair a run-up in rpm with the rotor's high modes); one eigen-solve per measured speed,
/// not charged to the fit's budget. Without such a slip nothing is refused here.
fn refuse_unit_slip(
    rotor: &Rotor,
    params: &[eigenfit_rotordynamics::identify::Parameter],
    initial: &[f64],
    points: &[RunupPoint],
    measured: &Path,
) -> Result<(), WorkflowError> {
    let all: Vec<&RunupPoint> = points.iter().collect();
    let Some(solved) = start_modes_at_speeds(rotor, params, initial, &all) else { return Ok(()) };
    let mut ratios = Vec::with_capacity(points.len());
    for p in points {
        let at = &solved.iter().find(|(rpm, _)| *rpm == p.speed_rpm).expect("solved").1;
        let Some(model) = at.get(p.mode - 1).map(|m| m.frequency_hz()).filter(|f| *f > 0.0) else {
            return Ok(());
        };
        ratios.push((p.frequency_hz / model, model));
    }
    let far = ratios.iter().all(|(r, _)| !(1.0 / RUNUP_SLIP_RATIO..=RUNUP_SLIP_RATIO).contains(r));
    let Some((unit, factor)) = RUNUP_UNIT_SLIPS
        .iter()
        .copied()
        .find(|(_, f)| far && ratios.iter().all(|(r, _)| (0.5..=2.0).contains(&(r * f))))
    else {
        return Ok(());
    };
    let (p, (_, model)) = (&points[0], ratios[0]);
    Err(input(format!(
        "{}: every measured frequency is {}× or more off the rotor's frequency of its mode (mode {} at {} rpm: \
         {} measured, the rotor at its starting bearings {:.4} Hz), more than bearing factors within \
         1e-3…1e3 can move it (√1000 ≈ 32×): the frequencies look entered in {unit}, not Hz; converted \
         (×{}) every one lies within a factor of 2 of the rotor's; give them in Hz",
        measured.display(),
        RUNUP_SLIP_RATIO,
        p.mode,
        p.speed_rpm,
        eigenfit_core::measurement::measured_csv::shown_number(p.frequency_hz),
        model,
        eigenfit_core::measurement::measured_csv::shown_number(factor)
    )))
}

/// The rotor at its starting coefficients, solved at each speed of `points` for its modes up to
/// the highest number measured there: what the up-front checks compare a run-up with, mode by
/// mode number (one eigen-solve per speed, not charged to the fit's budget). `None` when a speed
/// cannot be solved: the checks then judge nothing, and the fit says what is wrong.
fn start_modes_at_speeds(
    rotor: &Rotor,
    params: &[eigenfit_rotordynamics::identify::Parameter],
    initial: &[f64],
    points: &[&RunupPoint],
) -> Option<Vec<(f64, Vec<eigenfit_rotordynamics::Mode>)>> {
    let start = eigenfit_rotordynamics::identify::scaled_rotor(rotor, params, initial);
    let mut solved: Vec<(f64, Vec<eigenfit_rotordynamics::Mode>)> = Vec::new();
    for p in points {
        if !solved.iter().any(|(rpm, _)| *rpm == p.speed_rpm) {
            let highest =
                points.iter().filter(|q| q.speed_rpm == p.speed_rpm).map(|q| q.mode).max().unwrap_or(1);
            solved.push((p.speed_rpm, start.lowest_modes(rpm_to_rad(p.speed_rpm), highest).ok()?));
        }
    }
    Some(solved)
}

/// Refuses whirl labels every one of which contradicts the rotor: each point labelled forward
/// or backward (at least two such) has, at the starting coefficients, a model mode of its
/// number whirling the other way (a model mode whirling mixed judges nothing) — swapped labels or a reversed sense of rotation. The fit's pairing
/// only weighs a mismatch, so it would pair such labels with the wrong modes of a close
/// forward/backward pair and end in a poor fit; compared by mode number (as the unit-slip check)
/// with one eigen-solve per labelled speed, not charged to the budget. Points labelled mixed,
/// or not at all, are not judged.
fn refuse_reversed_whirl(
    rotor: &Rotor,
    params: &[eigenfit_rotordynamics::identify::Parameter],
    initial: &[f64],
    points: &[RunupPoint],
    measured: &Path,
) -> Result<(), WorkflowError> {
    use eigenfit_rotordynamics::Whirl;
    let labelled: Vec<&RunupPoint> =
        points.iter().filter(|p| matches!(p.whirl, Some(Whirl::Forward | Whirl::Backward))).collect();
    if labelled.len() < 2 {
        return Ok(());
    }
    let Some(solved) = start_modes_at_speeds(rotor, params, initial, &labelled) else { return Ok(()) };
    let mut contradicting = 0;
    for p in &labelled {
        let at = &solved.iter().find(|(rpm, _)| *rpm == p.speed_rpm).expect("solved").1;
        // A model mode that whirls mixed (or is missing) neither agrees nor contradicts.
        match (p.whirl, at.get(p.mode - 1).map(|m| &m.whirl)) {
            (Some(Whirl::Forward), Some(Whirl::Backward)) | (Some(Whirl::Backward), Some(Whirl::Forward)) => {
                contradicting += 1
            }
            (Some(w), Some(m)) if w == *m => return Ok(()),
            _ => {}
        }
    }
    if contradicting < 2 {
        return Ok(());
    }
    let p = labelled[0];
    Err(input(format!(
        "{}: every whirl label contradicts the rotor ({} of {} labelled points; none agrees): at its starting \
         bearings the rotor's mode of each number whirls the other way (e.g. mode {} at {} rpm, {} Hz, is labelled {}); are forward and \
         backward swapped, or the sense of rotation reversed? Correct the labels, or leave the whirl column \
         empty to pair by frequency alone",
        measured.display(),
        contradicting,
        labelled.len(),
        p.mode,
        p.speed_rpm,
        p.frequency_hz,
        p.whirl.map_or("", |w| w.name())
    )))
}

/// [`estimate`] with `--initial` and `--write-model` (see [`RunupOptions`]).
pub fn estimate_with(
    path: &Path,
    measured: &Path,
    options: &RunupOptions<'_>,
    max_iterations: usize,
    refits: usize,
    budget: usize,
) -> Result<RunupEstimateReport, WorkflowError> {
    let rotor = load(path)?;
    if rotor.has_whirl_tables() {
        return Err(input(format!(
            "{}: a bearing's coefficients are a table over whirl frequency; the run-up fit evaluates \
             bearings at the rotor speed and is not available for such rotors (simulate and campbell are)",
            path.display()
        )));
    }
    let points = read_runup(measured).map_err(to_workflow)?;
    let chosen: Vec<&str> = match options.selection {
        Some(list) => list.split(',').map(str::trim).filter(|s| !s.is_empty()).collect(),
        None => DEFAULT_COEFFICIENTS.to_vec(),
    };
    let params = bearing_parameters(&rotor, &chosen).map_err(|e| input(format!("--parameters: {e}")))?;
    if params.is_empty() {
        return Err(input(format!("{}: the rotor has no bearings to estimate", path.display())));
    }
    let w_lowest = rpm_to_rad(points.iter().map(|p| p.speed_rpm).fold(f64::INFINITY, f64::min));
    let initial = initial_factors(options.initial, &params, &rotor, w_lowest)?;
    let text = if options.write_model {
        Some(
            std::fs::read_to_string(path)
                .map_err(|e| input(format!("{}: cannot read: {e}", path.display())))?,
        )
    } else {
        None
    };
    // A mode number no rotor of this size has: refused naming it, not paired by frequency with
    // whatever mode is nearest (the number is the pairing's order hint).
    if let Some(p) = points.iter().find(|p| p.mode > rotor.dofs()) {
        return Err(input(format!(
            "{}: mode {} measured at {} rpm but the rotor ({} DOFs) has at most {} modes",
            measured.display(),
            p.mode,
            p.speed_rpm,
            rotor.dofs(),
            rotor.dofs()
        )));
    }
    // Both refusals are about what the measured file holds (how many points, at which speeds).
    check_selection(&rotor, &params, &points).map_err(|e| input(format!("{}: {e}", measured.display())))?;
    if budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    let objective = RunupObjective::new(&rotor, params.clone(), &points, None).map_err(to_workflow)?;
    refuse_unit_slip(&rotor, &params, &initial, &points, measured)?;
    refuse_reversed_whirl(&rotor, &params, &initial, &points, measured)?;
    let np = params.len();
    let budget = Budget::new(budget);
    let mut phases: Vec<(&str, usize)> = Vec::new();
    let (estimate, restarts) = match fit_runup(&objective, &params, &initial, max_iterations, refits, &budget)
    {
        Ok(f) => f,
        Err(_) if budget.exhausted() => {
            return Err(WorkflowError::BudgetExhausted(format!(
            "the budget of {} model evaluations ran out before the fit could start (raise it with --budget)",
            budget.limit()
        )))
        }
        Err(e) => return Err(input(format!("{}: {e}", measured.display()))),
    };
    phases.push(("fit", budget.used()));
    let mut estimate = estimate;
    let converged = estimate.termination.is_converged();
    // Mirrors (exchanges of like coefficients the rotor is symmetric under: two bearings alike),
    // then the search for other minima from a space-filling design, as for every model kind: a
    // run-up at one speed fits as many factors as frequencies, and another exact fit may exist.
    let (mut mirrors, mut minima) = (Mirrors::default(), Vec::new());
    let (mut better_note, mut search_note, mut search) = (None, Vec::new(), None);
    if converged {
        let exchanges = like_exchanges(&objective);
        mirrors = mirror_solutions(&objective, &estimate.last, &exchanges, &budget);
        phases.push(("mirror_solutions", budget.used()));
        // Screened: a run-up evaluation solves every speed, so the design is ranked by misfit and
        // only its best np + 1 points are fitted locally (fitting all cost ~300× the fit itself);
        // above 8 coefficients each local fit is budgeted as every model kind's is (a far start
        // in 12 dimensions wandered for ~400 evaluations).
        let starts = eigenfit_core::analysis::alternatives::search_starts(np);
        let extra = &mirrors.asymmetric;
        if let Some(keep) = screened_fits(np) {
            let screening = Screening { starts, keep, most_evaluations: None, predict_extra: false };
            let found = screened_search(&objective, &screening, extra, &budget, &Damped, &estimate.last);
            let report = SearchReport::of(&found, &screening, extra.len());
            search_note = report.note();
            minima = found.minima;
            search = Some(report);
        } else {
            minima = screened_local_minima(&objective, starts, np + 1, extra, &budget);
        }
        phases.push(("other_solutions", budget.used()));
        if let Some(better) = better_minimum(&objective, &estimate.last, &minima).cloned() {
            better_note = Some(adopt_better_minimum(&mut estimate, better, &mut minima));
            mirrors = mirror_solutions(&objective, &estimate.last, &exchanges, &budget);
        }
    } else {
        phases.push(("mirror_solutions", budget.used()));
    }
    let lin = &estimate.last;
    // Every bound a job on rayon's threads: the same intervals and evaluations as in series.
    let uncertainty = if converged { uncertainty_parallel(&objective, lin, &budget, &mut []) } else { None };
    phases.push(("intervals", budget.used()));
    let quality = judge(lin, np);
    let alternatives_sigma = Equivalence::at(lin, np).sigma_source();
    let mut alternatives = listed_alternatives(&objective, lin, mirrors.symmetric, &minima);
    let unique = !alternatives.iter().any(|m| m.judged.equally_good);
    let budget_spent = budget.exhausted();
    // estimate's rule: a coefficient on a limit of its factor is no acceptable answer.
    let on_limit = at_limits(eigenfit_core::problem::Objective::parameters(&objective), &estimate.parameters)
        .iter()
        .any(|&l| l != 0);
    let verdict = Verdict::of(
        (!converged).then(|| estimate.termination.label()),
        budget_spent,
        quality.verdict,
        on_limit,
        false,
        unique,
    );
    // Report each coefficient at the lowest measured speed (constant bearings: their value).
    let w0 = rpm_to_rad(points.iter().map(|p| p.speed_rpm).fold(f64::INFINITY, f64::min));
    let nominal: Vec<f64> = params.iter().map(|p| p.nominal(&rotor, w0)).collect();
    let physical =
        |factors: &[f64]| -> Vec<f64> { nominal.iter().zip(factors).map(|(k, s)| k * s).collect() };
    let value = physical(&estimate.parameters);
    let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
    // Factor intervals on the nominal coefficient, ordered low, high also for a negative
    // (cross-coupled) one.
    let intervals: Option<Vec<[f64; 2]>> = uncertainty.as_ref().map(|u| {
        u.intervals
            .iter()
            .zip(&nominal)
            .map(|(iv, k)| {
                let (a, b) = (iv[0] * k, iv[1] * k);
                [a.min(b), a.max(b)]
            })
            .collect()
    });
    let status = |i: usize| -> String {
        let id = uncertainty.as_ref().map(|u| &u.identifiability[i]);
        match (&intervals, id) {
            _ if !converged => "(not computed: the run did not converge)".into(),
            (Some(iv), Some(Identifiability::Determined)) => format!("[{:.4e}, {:.4e}]", iv[i][0], iv[i][1]),
            (_, Some(Identifiability::LowerBoundOnly { lower })) => {
                format!("not identifiable: factor ≥ {lower:.4e}")
            }
            (_, Some(Identifiability::UpperBoundOnly { upper })) => {
                format!("not identifiable: factor ≤ {upper:.4e}")
            }
            (_, Some(_)) => {
                "not identifiable: the frequencies fix only combinations of the parameters".into()
            }
            _ => "(no std given)".into(),
        }
    };
    for a in &mut alternatives {
        a.parameters = physical(&a.parameters);
    }
    // One more evaluation for the whirl of each paired model mode at the estimate.
    let whirl = evaluate(&rotor, &params, &estimate.parameters, &points).map_err(to_workflow)?.whirl;
    let updated_model = match text {
        Some(text) => {
            let changes: Vec<(String, String, f64)> = params
                .iter()
                .zip(&estimate.parameters)
                .map(|(p, s)| {
                    let b = &rotor.bearings[p.bearing];
                    let name = eigenfit_rotordynamics::identify::COEFFICIENT_NAMES[p.coefficient];
                    (b.tag.clone(), name.to_string(), *s)
                })
                .collect();
            Some(ross_file::write_scaled(&text, &changes).map_err(to_workflow)?)
        }
        None => None,
    };
    Ok(RunupEstimateReport {
        updated_model,
        estimated_rotor: eigenfit_rotordynamics::identify::scaled_rotor(
            &rotor,
            &params,
            &estimate.parameters,
        ),
        history: estimate.history.clone(),
        search,
        model: path.display().to_string(),
        outcome: Outcome::of(&estimate, converged),
        verdict,
        fit: FitQualityReport::of(&quality, |k| RunupPointId {
            speed_rpm: points[k].speed_rpm,
            mode: points[k].mode,
        }),
        budget: BudgetReport::of(&budget),
        evaluations_by_phase: phase_counts(&phases),
        reference_speed_rpm: w0 * 30.0 / std::f64::consts::PI,
        // `initial`: where the fit started (the file's values, or --initial's).
        values: ParameterValues::new(
            &names,
            &nominal.iter().zip(&initial).map(|(k, f)| k * f).collect::<Vec<_>>(),
            &value,
            status,
        ),
        scales: Named::new(&names, estimate.parameters.iter().copied()),
        units: Named::new(&names, params.iter().map(|p| p.unit().to_string())),
        // Coefficient = nominal × factor: cov(kᵢ, kⱼ) = nominalᵢ·nominalⱼ·cov(factorᵢ, factorⱼ).
        covariances: Covariances::of(
            &names,
            uncertainty
                .as_ref()
                .map(|u| {
                    eigenfit_core::nalgebra::DMatrix::from_fn(np, np, |i, j| {
                        u.covariance[(i, j)] * nominal[i] * nominal[j]
                    })
                })
                .as_ref(),
        ),
        cost: lin.chi2(),
        intervals: intervals.map(|iv| Named::new(&names, iv)),
        identifiable: uncertainty
            .as_ref()
            .map(|u| Named::new(&names, u.identifiability.iter().map(Into::into))),
        refits: restarts,
        alternative_solutions: AlternativeSolution::list(&names, &alternatives),
        alternatives_sigma,
        notes: {
            let mut notes = Vec::new();
            if options.initial.is_some() {
                let start: Vec<String> = params
                    .iter()
                    .zip(&initial)
                    .zip(&nominal)
                    .map(|((p, f), k)| format!("{} = {:.6e} (×{f:.6} the file's)", p.name, k * f))
                    .collect();
                notes.push(format!("the fit started from --initial: {}", start.join(", ")));
            }
            notes.extend(rotor.extrapolation_notes(&points.iter().map(|p| p.speed_rpm).collect::<Vec<_>>()));
            notes.extend(search_note);
            notes.extend(better_note);
            notes
        },
        points: points
            .iter()
            .enumerate()
            .map(|(i, p)| RunupPointReport {
                speed_rpm: p.speed_rpm,
                mode: p.mode,
                measured_hz: p.frequency_hz,
                model_hz: lin.frequencies_hz[i],
                model_whirl: whirl[i].name(),
                measured_whirl: p.whirl.map(|w| w.name()),
            })
            .collect(),
        plots: None,
    })
}

/// One run-up point before and after the discovered effects: its speed and the keys of a
/// planar `discover`'s mode (`mode` as measured at that speed, `measured_hz`, `std_hz` —
/// assumed where the file gives none —, `before_hz`, `after_hz`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupDiscoveryPoint {
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// The mode before and after.
    #[serde(flatten)]
    pub mode: crate::discover::ModeReport,
}

/// `discover` on a two-plane rotor: the planar report's keys (`missing_effect`, `chi2_before`,
/// `calibrated_parameters` — the bearings' kxx and kyy in N/m at `reference_speed_rpm` —, …),
/// and each run-up point by speed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupDiscoverReport {
    /// The report every model gives.
    #[serde(flatten)]
    pub discovery: crate::discover::DiscoverReport,
    /// The speed the coefficients are given at (the lowest measured, rpm).
    pub reference_speed_rpm: f64,
    /// Each run-up point, before and after.
    pub points: Vec<RunupDiscoveryPoint>,
}

/// `discover --model ROSS-FILE --measured RUNUP.csv`: calibrate the bearings' kxx and kyy, test
/// the misfit against the noise and, when it is significant, name the effects (a mass, a
/// diametral or polar inertia at a node, cross-coupling at a bearing, a stiffness loss in a
/// shaft element) that explain it, by core's forward selection.
/// `budget`: most model evaluations (each one eigen-solve round over the run-up's speeds).
pub fn discover(
    path: &Path,
    measured: &Path,
    assumed_std: f64,
    budget: usize,
) -> Result<RunupDiscoverReport, WorkflowError> {
    use eigenfit_core::discovery::{discover_effects, DiscoveryOptions};
    use eigenfit_rotordynamics::effects::candidates;
    use eigenfit_rotordynamics::objective::{RunupObjective, RunupSearch, DISCOVERY_FACTOR_RANGE};
    if !(assumed_std.is_finite() && assumed_std > 0.0) {
        return Err(input(format!("--assumed-std {assumed_std}: must be a positive number")));
    }
    let rotor = load(path)?;
    let points = read_runup(measured).map_err(to_workflow)?;
    let params = bearing_parameters(&rotor, &DEFAULT_COEFFICIENTS).map_err(to_workflow)?;
    if params.is_empty() {
        return Err(input(format!("{}: the rotor has no bearings to calibrate", path.display())));
    }
    let (lower, upper) = DISCOVERY_FACTOR_RANGE;
    let base = RunupObjective::new(&rotor, params.clone(), &points, Some(assumed_std))
        .and_then(|o| o.within(lower, upper))
        .map_err(to_workflow)?;
    let filled: Vec<RunupPoint> = base.points().to_vec();
    let effects = candidates(&rotor);
    let search = RunupSearch::new(base, &effects);
    let options =
        DiscoveryOptions { assumed_relative_std: assumed_std, max_evaluations: budget, ..Default::default() };
    let r =
        discover_effects(&search, &search.candidates(), &vec![1.0; params.len()], &options).map_err(|e| {
            match e {
                // The user's budget was too small for the calibration: no input error.
                eigenfit_core::discovery::DiscoveryError::BudgetExhausted(_) => {
                    crate::discover::budget_error(budget)
                }
                e => input(format!("{}: {e}", measured.display())),
            }
        })?;
    let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
    let mut report = crate::discover::report_of(
        &path.display().to_string(),
        &r,
        &r.effects,
        1,
        &names,
        options.max_evaluations,
    );
    // Factors → N/m at the lowest measured speed, as `estimate` reports them.
    let w0 = rpm_to_rad(points.iter().map(|p| p.speed_rpm).fold(f64::INFINITY, f64::min));
    let nominal: Vec<f64> = params.iter().map(|p| p.nominal(&rotor, w0)).collect();
    for ((_, v), k) in report.calibrated_parameters.0.iter_mut().zip(&nominal) {
        *v *= k;
    }
    if let Some(refitted) = report.refitted_parameters.as_mut() {
        for ((_, v), k) in refitted.0.iter_mut().zip(&nominal) {
            v.value *= k;
            v.interval = v.interval.map(|[a, b]| [a * k, b * k]);
        }
    }
    let points = filled
        .iter()
        .zip(&r.modes)
        .map(|(p, m)| RunupDiscoveryPoint {
            speed_rpm: p.speed_rpm,
            mode: crate::discover::ModeReport {
                mode: p.mode,
                measured_hz: p.frequency_hz,
                std_hz: m.std_hz,
                before_hz: m.before_hz,
                after_hz: m.after_hz,
            },
        })
        .collect();
    Ok(RunupDiscoverReport {
        discovery: report,
        reference_speed_rpm: w0 * 30.0 / std::f64::consts::PI,
        points,
    })
}

/// Parses `FROM:TO:COUNT` (rpm, linear).
pub fn parse_speeds(text: &str) -> Result<Vec<f64>, WorkflowError> {
    let bad = |why: &str| {
        input(format!("--speeds `{text}`: {why} (expected FROM:TO:COUNT in rpm, e.g. 0:12000:50)"))
    };
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    let [from, to, count] = parts[..] else { return Err(bad("three fields needed")) };
    let from: f64 = from.parse().map_err(|_| bad("FROM is not a number"))?;
    let to: f64 = to.parse().map_err(|_| bad("TO is not a number"))?;
    let count: usize = count.parse().map_err(|_| bad("COUNT is not a whole number"))?;
    if !from.is_finite() || !to.is_finite() || from < 0.0 || to < from {
        return Err(bad("speeds must be finite with 0 ≤ FROM ≤ TO"));
    }
    if count == 0 || count > 100_000 || (count == 1 && to != from) {
        return Err(bad("COUNT must be 1 … 100000 (1 only when FROM = TO)"));
    }
    eigenfit_rotordynamics::check_speed_rpm(to).map_err(|e| bad(&format!("TO: {e}")))?;
    Ok((0..count)
        .map(|i| if count == 1 { from } else { from + (to - from) * i as f64 / (count - 1) as f64 })
        .collect())
}

/// The Campbell diagram of a two-plane rotor: the diagram's own keys (`speeds_rpm`,
/// `frequencies_hz`, `whirl`, `log_dec`, `curves`, `critical_speeds`) and these.
#[derive(Debug, Clone, Serialize)]
pub struct CampbellReport {
    /// `--operating`: the operating range (rpm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operating_range_rpm: Option<[f64; 2]>,
    /// `--operating`: each critical speed's separation margin from the range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub separation_margins: Option<Vec<SeparationMargin>>,
    /// The model file.
    pub model: String,
    /// The diagram.
    #[serde(flatten)]
    pub campbell: Campbell,
    /// The critical speeds (rpm).
    pub critical_speeds_rpm: Vec<f64>,
    /// Rigid-body modes at the first speed, left out of the modes listed and of the critical
    /// speeds (a rotor without bearings or seals); absent when there are none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rigid_body_modes_left_out: Option<usize>,
    /// Plot files written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plots: Option<Vec<String>>,
    /// Bearing tables extrapolated, speeds with unstable modes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// `campbell`: damped frequencies, whirl and log decrement of a ROSS rotor against speed.
pub fn campbell_diagram(path: &Path, speeds: &str, modes: usize) -> Result<CampbellReport, WorkflowError> {
    let speeds = parse_speeds(speeds)?;
    require_ross(path, "campbell")?;
    let rotor = load(path)?;
    if modes == 0 {
        return Err(input("--modes 0: at least one mode"));
    }
    let c = campbell(&rotor, &speeds, modes).map_err(|e| match e {
        // A solver failure (a whirl-frequency fixed point that does not settle) is no input error.
        RotorDynError::Solver(m) => WorkflowError::Failure(format!("{}: {m}", path.display())),
        other => input(format!("{}: {other}", path.display())),
    })?;
    let mut notes = rotor.extrapolation_notes(&speeds);
    let rigid = rotor.rigid_body_modes(rpm_to_rad(speeds[0])).map_err(to_workflow)?;
    notes.extend(rigid_body_note(rigid, speeds[0]));
    // Static instability at either end of the sweep (bearing tables change with speed).
    let ends = [speeds[0], speeds[speeds.len() - 1]];
    notes.extend(
        ends.iter().take(if ends[0] == ends[1] { 1 } else { 2 }).find_map(|&r| divergent_note(&rotor, r)),
    );
    let whirl = c.frequencies_hz.iter().flatten().map(|f| 2.0 * std::f64::consts::PI * f);
    let (lo, hi) = whirl.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), w| (a.min(w), b.max(w)));
    if lo.is_finite() {
        notes.extend(rotor.whirl_extrapolation_notes(&[lo, hi]));
    }
    let unstable: Vec<String> = (0..speeds.len())
        .filter(|&k| c.log_dec[k].iter().any(|&d| d < 2.0 * std::f64::consts::PI * UNSTABLE_BELOW))
        .map(|k| format!("{:.0}", speeds[k]))
        .collect();
    if !unstable.is_empty() {
        notes.push(format!(
            "a mode with negative damping ratio (unstable: the vibration grows) at {} of the speeds: {} rpm",
            unstable.len(),
            unstable.join(", ")
        ));
    }
    Ok(CampbellReport {
        model: path.display().to_string(),
        critical_speeds_rpm: c.critical_speeds.iter().map(|k| k.rpm).collect(),
        campbell: c,
        rigid_body_modes_left_out: (rigid > 0).then_some(rigid),
        plots: None,
        notes,
        operating_range_rpm: None,
        separation_margins: None,
    })
}

/// One critical speed against the operating range, API 684 style (API 617's rule for the
/// required separation margin from the amplification factor).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeparationMargin {
    /// The critical speed (rpm).
    pub rpm: f64,
    /// Its damping ratio ζ.
    pub damping_ratio: f64,
    /// Amplification factor 1/(2ζ) (`null` for ζ ≤ 0: no finite peak, unstable or undamped).
    pub amplification_factor: Option<f64>,
    /// Required margin (% of the nearer end of the operating range): none when AF < 2.5
    /// (critically damped); 5 % below / 15 % above for 2.5 ≤ AF ≤ 3.55; above that
    /// 16(1 − 1/(AF − 1.5)) % below and 10 + 17(1 − 1/(AF − 1.5)) % above (AF → ∞ for ζ ≤ 0).
    pub required_margin_percent: f64,
    /// Actual margin (% of the nearer end: (min − Nc)/min below, (Nc − max)/max above;
    /// negative inside the operating range).
    pub margin_percent: f64,
    /// `below`, `inside` or `above` the operating range.
    pub position: &'static str,
    /// Whether the actual margin is at least the required one.
    pub passes: bool,
}

/// The separation margins of `critical` against the operating range [lo, hi] rpm.
pub fn separation_margins(
    critical: &[eigenfit_rotordynamics::campbell::CriticalSpeed],
    lo: f64,
    hi: f64,
) -> Vec<SeparationMargin> {
    critical
        .iter()
        .map(|k| {
            // ζ within round-off of 0 (an undamped rotor's come out within ±1e-13): no finite AF.
            let af = (k.damping_ratio > -UNSTABLE_BELOW).then(|| 1.0 / (2.0 * k.damping_ratio));
            let a = af.unwrap_or(f64::INFINITY);
            let (position, margin) = if k.rpm < lo {
                ("below", 100.0 * (lo - k.rpm) / lo)
            } else if k.rpm > hi {
                ("above", 100.0 * (k.rpm - hi) / hi)
            } else {
                ("inside", -100.0 * ((k.rpm - lo) / lo.max(1e-300)).min((hi - k.rpm) / hi))
            };
            let below = position != "above" && (position == "below" || k.rpm - lo < hi - k.rpm);
            let required = if a < 2.5 {
                0.0
            } else if a <= 3.55 {
                if below {
                    5.0
                } else {
                    15.0
                }
            } else {
                let r = 1.0 - 1.0 / (a - 1.5);
                if below {
                    16.0 * r
                } else {
                    10.0 + 17.0 * r
                }
            };
            let passes = required == 0.0 || (position != "inside" && margin >= required);
            SeparationMargin {
                rpm: k.rpm,
                damping_ratio: k.damping_ratio,
                amplification_factor: af,
                required_margin_percent: required,
                margin_percent: margin,
                position,
                passes,
            }
        })
        .collect()
}

/// [`campbell_diagram`] with `--operating FROM:TO` (rpm): each critical speed's API 684-style
/// separation margin from the operating range.
pub fn campbell_diagram_with(
    path: &Path,
    speeds: &str,
    modes: usize,
    operating: Option<&str>,
) -> Result<CampbellReport, WorkflowError> {
    let range = match operating {
        None => None,
        Some(text) => {
            let bad = |why: &str| {
                input(format!("--operating `{text}`: {why} (expected FROM:TO in rpm, e.g. 9000:11000)"))
            };
            let (a, b) = text.split_once(':').ok_or_else(|| bad("two fields needed"))?;
            let a: f64 = a.trim().parse().map_err(|_| bad("FROM is not a number"))?;
            let b: f64 = b.trim().parse().map_err(|_| bad("TO is not a number"))?;
            if !(a.is_finite() && b.is_finite() && a > 0.0 && b >= a) {
                return Err(bad("speeds must be finite with 0 < FROM ≤ TO"));
            }
            Some((a, b))
        }
    };
    let mut report = campbell_diagram(path, speeds, modes)?;
    if let Some((lo, hi)) = range {
        let swept = report.campbell.speeds_rpm.iter().copied().fold(0.0, f64::max);
        // The largest margin API 617 can require above the range is 27 %.
        if swept < hi * 1.27 {
            report.notes.push(format!(
                "--operating {lo}:{hi}: the sweep ends at {swept} rpm, below {:.0} rpm (27 % above the range, the \
                 largest margin required): critical speeds above it are not checked",
                hi * 1.27
            ));
        }
        // The amplification factor 1/(2ζ) needs ζ at the crossing itself: each critical speed is
        // refined on the rotor (a coarse sweep's interpolated ζ can be off by half).
        let rotor = load(path)?;
        let refined = report
            .campbell
            .critical_speeds
            .iter()
            .map(|k| refine_critical_speed(&rotor, &report.campbell, k, modes))
            .collect::<Result<Vec<_>, _>>()
            .map_err(to_workflow)?;
        if !refined.is_empty() {
            report.notes.push(format!(
                "--operating: the {} critical speed(s) were refined on the rotor (the 1× crossing solved to 1e-10, \
                 each within its two swept speeds): their speeds, damping ratios and amplification factors are at \
                 the crossing, not interpolated between swept speeds",
                refined.len()
            ));
        }
        report.critical_speeds_rpm = refined.iter().map(|k| k.rpm).collect();
        report.campbell.critical_speeds = refined;
        report.separation_margins = Some(separation_margins(&report.campbell.critical_speeds, lo, hi));
        report.operating_range_rpm = Some([lo, hi]);
    }
    Ok(report)
}

/// Speeds of the Campbell diagram drawn at a run-up estimate: 0 to 20 % above the highest
/// measured speed, so the critical speeds just above the run-up show.
const ESTIMATE_CAMPBELL_SPEEDS: usize = 41;

/// The Campbell diagram of the rotor at a run-up estimate (its estimated rotor), from 0 to 1.2 ×
/// the highest measured speed, with as many modes as the run-up measured: what `estimate --plot`
/// draws beside the run-up fit.
pub fn campbell_at_estimate(report: &RunupEstimateReport) -> Result<Campbell, WorkflowError> {
    let rotor = &report.estimated_rotor;
    let top = top_measured_rpm(report) * 1.2;
    let speeds: Vec<f64> = (0..ESTIMATE_CAMPBELL_SPEEDS)
        .map(|i| top * i as f64 / (ESTIMATE_CAMPBELL_SPEEDS - 1) as f64)
        .collect();
    campbell(rotor, &speeds, measured_modes(report)).map_err(to_workflow)
}

/// The highest speed of the run-up (rpm).
pub fn top_measured_rpm(report: &RunupEstimateReport) -> f64 {
    report.points.iter().map(|p| p.speed_rpm).fold(0.0, f64::max)
}

/// How many modes the run-up measured (its highest mode number), at most the rotor's DOFs.
fn measured_modes(report: &RunupEstimateReport) -> usize {
    report.points.iter().map(|p| p.mode).max().unwrap_or(1).min(report.estimated_rotor.dofs())
}

/// The mode shapes and orbits of the rotor at a run-up estimate, at the top measured speed, of
/// the modes the run-up measured: what `estimate --plot` draws beside the Campbell diagram.
pub fn shapes_at_estimate(report: &RunupEstimateReport) -> Result<RotorShapes, WorkflowError> {
    let rpm = top_measured_rpm(report);
    RotorShapes::of(&report.estimated_rotor, rpm, measured_modes(report)).map_err(to_workflow)
}

/// The mode shapes and orbits of the modes `simulate --model ROSS-FILE --speed RPM --modes N
/// [--set …]` listed (what `simulate --plot` draws), on the rotor it solved.
pub fn shapes_of(report: &SpeedReport) -> Result<RotorShapes, WorkflowError> {
    RotorShapes::of(&report.rotor, report.speed_rpm, report.frequencies_hz.len()).map_err(to_workflow)
}

#[cfg(test)]
mod margin_tests {
    use super::*;
    use eigenfit_rotordynamics::campbell::CriticalSpeed;
    use eigenfit_rotordynamics::Whirl;

    fn at(rpm: f64, zeta: f64) -> CriticalSpeed {
        CriticalSpeed { rpm, curve: 0, whirl: Whirl::Forward, log_dec: 0.0, damping_ratio: zeta }
    }

    /// API 617's required margins: none below AF 2.5; 5 % below / 15 % above up to AF 3.55;
    /// 16(1 − 1/(AF − 1.5)) % below and 10 + 17(1 − 1/(AF − 1.5)) % above beyond; AF 1/(2ζ).
    #[test]
    fn required_margins_follow_the_amplification_factor() {
        let m = separation_margins(
            &[
                at(5000.0, 0.25),
                at(8000.0, 1.0 / 6.0),
                at(9000.0, 1.0 / 11.0),
                at(14_000.0, 1.0 / 11.0),
                at(13_000.0, 1e-14),
            ],
            10_000.0,
            12_000.0,
        );
        assert_eq!(m[0].required_margin_percent, 0.0); // AF 2
        assert!(m[0].passes);
        assert_eq!((m[1].required_margin_percent, m[1].position), (5.0, "below")); // AF 3
        assert!((m[1].margin_percent - 20.0).abs() < 1e-12 && m[1].passes);
        assert!((m[2].required_margin_percent - 12.0).abs() < 1e-12); // AF 5.5, below
        assert!((m[2].margin_percent - 10.0).abs() < 1e-12 && !m[2].passes);
        assert!((m[3].required_margin_percent - 22.75).abs() < 1e-12); // AF 5.5, above
        assert!((m[3].margin_percent - 100.0 * 2000.0 / 12_000.0).abs() < 1e-12 && !m[3].passes);
        assert_eq!(m[4].amplification_factor, None); // undamped: AF infinite
        assert_eq!((m[4].position, m[4].required_margin_percent), ("above", 27.0));
        assert!(m[4].margin_percent > 8.3 && !m[4].passes);
        let inside = separation_margins(&[at(11_000.0, 0.01)], 10_000.0, 12_000.0);
        assert_eq!(inside[0].position, "inside");
        assert!(inside[0].margin_percent < 0.0 && !inside[0].passes);
    }
}

#[cfg(test)]
mod tests {
    use super::parse_speeds;

    #[test]
    fn speeds_are_linear_and_inclusive() {
        assert_eq!(parse_speeds("0:1000:5").unwrap(), vec![0.0, 250.0, 500.0, 750.0, 1000.0]);
        assert_eq!(parse_speeds("300:300:1").unwrap(), vec![300.0]);
        for bad in ["0:10", "a:1:2", "10:0:3", "0:10:0", "-5:10:3", "0:10:1"] {
            assert!(parse_speeds(bad).is_err(), "{bad}");
        }
    }
}
