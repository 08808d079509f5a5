//! Two-plane rotors (files written by ROSS `Rotor.save`): damped modes at one speed, bearing
//! stiffnesses from run-up frequencies, and the Campbell diagram.

use crate::error::{input, WorkflowError};
use crate::named::Named;
use crate::outcome::Outcome;
use eigenfit_rotordynamics::identify::{identify, read_runup, stiffness_parameters};
use eigenfit_rotordynamics::{campbell, ross_file, rpm_to_rad, Campbell, Rotor, RotorDynError};
use serde::Serialize;
use std::path::Path;

/// The model file if it is a ROSS rotor (judged by its content: tables `ShaftElement_…`).
pub fn ross_model(path: Option<&Path>) -> Option<&Path> {
    let path = path?;
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
}

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
    Ok(SpeedReport {
        model: path.display().to_string(),
        speed_rpm: rpm,
        frequencies_hz: shown.iter().map(|m| m.frequency_hz()).collect(),
        natural_frequencies_hz: shown.iter().map(|m| m.natural_frequency_hz()).collect(),
        whirl: shown.iter().map(|m| m.whirl.name()).collect(),
        damping_ratio: shown.iter().map(|m| m.damping_ratio()).collect(),
        log_dec: shown.iter().map(|m| m.log_dec()).collect(),
        dofs: rotor.dofs(),
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

/// Bearing stiffnesses of a two-plane rotor from run-up frequencies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupEstimateReport {
    /// The model file.
    pub model: String,
    /// Converged, why it stopped, iterations, eigen-solve rounds.
    #[serde(flatten)]
    pub outcome: Outcome,
    /// The speed the stiffnesses are reported at (the lowest measured, rpm).
    pub reference_speed_rpm: f64,
    /// Nominal stiffnesses (N/m).
    pub initial: Named<f64>,
    /// Estimated stiffnesses (N/m).
    pub parameters: Named<f64>,
    /// Estimated scale factors on the nominal curves.
    pub scales: Named<f64>,
    /// Σ r².
    pub cost: f64,
    /// Whether every parameter is determined by the data.
    pub identifiable: bool,
    /// The run-up points at the estimate.
    pub points: Vec<RunupPointReport>,
    /// Intervals and χ², with std only.
    #[serde(flatten)]
    pub with_std: Option<RunupIntervals>,
}

/// The part of a run-up estimate that needs standard deviations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunupIntervals {
    /// 95 % intervals (log-normal).
    pub intervals: Named<[f64; 2]>,
    /// Standard deviations of ln k.
    pub standard_deviations_ln: Named<f64>,
    /// χ² (the cost).
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: usize,
}

/// `estimate --model ROSS-FILE --measured RUNUP.csv`: kxx and kyy of every bearing.
pub fn estimate(
    path: &Path,
    measured: &Path,
    max_iterations: usize,
) -> Result<RunupEstimateReport, WorkflowError> {
    let rotor = load(path)?;
    let points = read_runup(measured).map_err(to_workflow)?;
    let params = stiffness_parameters(&rotor);
    if params.is_empty() {
        return Err(input(format!("{}: the rotor has no bearings to estimate", path.display())));
    }
    let initial = vec![1.0; params.len()];
    let id = identify(&rotor, &params, &points, &initial, max_iterations).map_err(to_workflow)?;
    // Report each stiffness in N/m at the lowest measured speed (constant bearings: their value).
    let w0 = rpm_to_rad(points.iter().map(|p| p.speed_rpm).fold(f64::INFINITY, f64::min));
    let nominal: Vec<f64> = params.iter().map(|p| rotor.bearings[p.bearing].k[p.entry].at(w0)).collect();
    let value: Vec<f64> = nominal.iter().zip(&id.scales).map(|(k, s)| k * s).collect();
    let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
    // 95 % intervals, log-normal (the estimate is linearised in ln k).
    let with_std = id.ln_std.as_ref().map(|sd| RunupIntervals {
        intervals: Named::new(
            &names,
            value.iter().zip(sd).map(|(v, s)| [v * (-1.96 * s).exp(), v * (1.96 * s).exp()]),
        ),
        standard_deviations_ln: Named::new(&names, sd.iter().copied()),
        chi2: id.cost,
        dof: points.len().saturating_sub(params.len()),
    });
    Ok(RunupEstimateReport {
        model: path.display().to_string(),
        outcome: Outcome {
            converged: id.converged,
            termination: id.reason.clone(),
            iterations: id.iterations,
            evaluations: id.evaluations,
        },
        reference_speed_rpm: w0 * 30.0 / std::f64::consts::PI,
        initial: Named::new(&names, nominal.iter().copied()),
        parameters: Named::new(&names, value.iter().copied()),
        scales: Named::new(&names, id.scales.iter().copied()),
        cost: id.cost,
        identifiable: id.identifiable,
        points: points
            .iter()
            .enumerate()
            .map(|(i, p)| RunupPointReport {
                speed_rpm: p.speed_rpm,
                mode: p.mode,
                measured_hz: p.frequency_hz,
                model_hz: id.model_hz[i],
                model_whirl: id.model_whirl[i].name(),
                measured_whirl: p.whirl.map(|w| w.name()),
            })
            .collect(),
        with_std,
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
}

/// `campbell`: damped frequencies, whirl and log decrement of a ROSS rotor against speed.
pub fn campbell_diagram(path: &Path, speeds: &str, modes: usize) -> Result<CampbellReport, WorkflowError> {
    let speeds = parse_speeds(speeds)?;
    let rotor = load(path)?;
    if modes == 0 {
        return Err(input("--modes 0: at least one mode"));
    }
    let c = campbell(&rotor, &speeds, modes).map_err(|e| input(format!("{}: {e}", path.display())))?;
    Ok(CampbellReport {
        model: path.display().to_string(),
        critical_speeds_rpm: c.critical_speeds.iter().map(|k| k.rpm).collect(),
        campbell: c,
        plots: None,
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
