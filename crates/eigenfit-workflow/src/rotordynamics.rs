//! Two-plane rotors (files written by ROSS `Rotor.save`): damped modes at one speed, bearing
//! stiffnesses from run-up frequencies, and the Campbell diagram.

use crate::error::{input, WorkflowError};
use crate::named::Named;
use crate::outcome::{
    phase_counts, AlternativeSolution, BudgetReport, FitQualityReport, Outcome, ParameterIdentifiability,
    ParameterValues, Verdict,
};
use eigenfit_core::analysis::alternatives::{like_exchanges, mirror_solutions, Equivalence};
use eigenfit_core::analysis::verdict::judge;
use eigenfit_core::analysis::{uncertainty_within, Identifiability};
use eigenfit_core::update::Budget;
use eigenfit_rotordynamics::fit::fit_runup;
use eigenfit_rotordynamics::identify::{
    bearing_parameters, check_selection, evaluate, read_runup, RunupPoint, DEFAULT_COEFFICIENTS,
};
use eigenfit_rotordynamics::objective::RunupObjective;
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

/// Loads a ROSS rotor, errors naming the file.
pub fn load(path: &Path) -> Result<Rotor, WorkflowError> {
    crate::model::check_model_file(path)?;
    ross_file::read(path).map_err(to_workflow)
}

fn check_speed(flag: &str, rpm: f64) -> Result<(), WorkflowError> {
    if !rpm.is_finite() || rpm < 0.0 {
        return Err(input(format!("{flag} {rpm}: speed must be a finite number of rpm ≥ 0")));
    }
    Ok(())
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
    /// The rotor's DOFs.
    #[serde(skip)]
    pub dofs: usize,
    /// What the numbers rest on that a reader should know: bearing tables extrapolated,
    /// unstable modes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// Damping ratio below which a mode is called unstable: an undamped rotor's come out of the
/// eigen-solver within ±1e-13 of 0 (rotor_example: |ζ| ≤ 6.2e-14 at 0 and 5000 rpm).
const UNSTABLE_BELOW: f64 = -1e-9;

/// `simulate --model ROSS-FILE [--speed RPM] --modes N`: damped modes at one speed.
pub fn simulate(path: &Path, speed_rpm: Option<f64>, modes: usize) -> Result<SpeedReport, WorkflowError> {
    let rotor = load(path)?;
    let rpm = speed_rpm.unwrap_or(0.0);
    check_speed("--speed", rpm)?;
    if modes == 0 || modes > rotor.dofs() {
        return Err(input(format!("--modes {modes}: must be between 1 and {} for this rotor", rotor.dofs())));
    }
    let all = rotor.lowest_modes(rpm_to_rad(rpm), modes).map_err(to_workflow)?;
    if modes > all.len() {
        return Err(input(format!(
            "--modes {modes}: must be between 1 and {} (the oscillating modes of this rotor at {rpm} rpm)",
            all.len()
        )));
    }
    let shown = &all[..modes];
    let mut notes = rotor.extrapolation_notes(&[rpm]);
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
        dofs: rotor.dofs(),
        notes,
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
    /// How σ was taken for the alternatives' test: `std`, `residuals` or `exact`.
    pub alternatives_sigma: &'static str,
    /// The run-up points at the estimate.
    pub points: Vec<RunupPointReport>,
    /// Bearing tables extrapolated at measured speeds.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
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
    let rotor = load(path)?;
    let points = read_runup(measured).map_err(to_workflow)?;
    let chosen: Vec<&str> = match selection {
        Some(list) => list.split(',').map(str::trim).filter(|s| !s.is_empty()).collect(),
        None => DEFAULT_COEFFICIENTS.to_vec(),
    };
    let params = bearing_parameters(&rotor, &chosen).map_err(|e| input(format!("--parameters: {e}")))?;
    if params.is_empty() {
        return Err(input(format!("{}: the rotor has no bearings to estimate", path.display())));
    }
    check_selection(&rotor, &params, &points).map_err(to_workflow)?;
    if budget == 0 {
        return Err(input("--budget 0: at least one model evaluation is needed"));
    }
    let objective = RunupObjective::new(&rotor, params.clone(), &points, None).map_err(to_workflow)?;
    let np = params.len();
    let initial = vec![1.0; np];
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
    let converged = estimate.termination.is_converged();
    let lin = &estimate.last;
    let has_std = lin.has_std;
    // Mirrors: exchanges of like coefficients the rotor is symmetric under (two bearings alike).
    let mirrors = if converged {
        mirror_solutions(&objective, lin, &like_exchanges(&objective), &budget)
    } else {
        Default::default()
    };
    phases.push(("mirror_solutions", budget.used()));
    let uncertainty = if converged { uncertainty_within(&objective, lin, has_std, &budget) } else { None };
    phases.push(("intervals", budget.used()));
    let quality = judge(lin, np);
    let equivalence = Equivalence::at(lin, np);
    let alternatives_sigma = if has_std {
        "std"
    } else if equivalence.sigma_estimated() {
        "residuals"
    } else {
        "exact"
    };
    let unique = !mirrors.symmetric.iter().any(|m| m.judged.equally_good);
    let budget_spent = budget.exhausted();
    let verdict = Verdict::of(
        (!converged).then(|| estimate.termination.label()),
        budget_spent,
        quality.verdict,
        false,
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
    let mut alternatives = mirrors.symmetric.clone();
    for a in &mut alternatives {
        a.parameters = physical(&a.parameters);
    }
    // One more evaluation for the whirl of each paired model mode at the estimate.
    let whirl = evaluate(&rotor, &params, &estimate.parameters, &points).map_err(to_workflow)?.whirl;
    Ok(RunupEstimateReport {
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
        values: ParameterValues::new(&names, &nominal, &value, status),
        scales: Named::new(&names, estimate.parameters.iter().copied()),
        cost: lin.chi2(),
        intervals: intervals.map(|iv| Named::new(&names, iv)),
        identifiable: uncertainty
            .as_ref()
            .map(|u| Named::new(&names, u.identifiability.iter().map(Into::into))),
        refits: restarts,
        alternative_solutions: AlternativeSolution::list(&names, &alternatives),
        alternatives_sigma,
        notes: rotor.extrapolation_notes(&points.iter().map(|p| p.speed_rpm).collect::<Vec<_>>()),
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
    Ok((0..count)
        .map(|i| if count == 1 { from } else { from + (to - from) * i as f64 / (count - 1) as f64 })
        .collect())
}

/// The Campbell diagram of a two-plane rotor: the diagram's own keys (`speeds_rpm`,
/// `frequencies_hz`, `whirl`, `log_dec`, `curves`, `critical_speeds`) and these.
#[derive(Debug, Clone, Serialize)]
pub struct CampbellReport {
    /// The model file.
    pub model: String,
    /// The diagram.
    #[serde(flatten)]
    pub campbell: Campbell,
    /// The critical speeds (rpm).
    pub critical_speeds_rpm: Vec<f64>,
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
    let rotor = load(path)?;
    if modes == 0 {
        return Err(input("--modes 0: at least one mode"));
    }
    let c = campbell(&rotor, &speeds, modes).map_err(|e| input(format!("{}: {e}", path.display())))?;
    let mut notes = rotor.extrapolation_notes(&speeds);
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
        plots: None,
        notes,
    })
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
