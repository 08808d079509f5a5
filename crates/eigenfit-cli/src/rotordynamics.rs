//! Two-plane rotors (files written by ROSS `Rotor.save`) in `simulate`, `estimate` and
//! `campbell`: the hooks in those commands route here when the model file is a ROSS rotor.

use crate::error::{input, CliError, EXIT_NOT_CONVERGED, EXIT_OK};
use eigenfit_core::analysis::verdict::{judge, FitQuality, FitVerdict};
use eigenfit_core::problem::Linearisation;
use eigenfit_rotordynamics::identify::{
    bearing_parameters, identify, read_runup, Identification, RunupPoint, DEFAULT_COEFFICIENTS,
};
use eigenfit_rotordynamics::{ross_file, rpm_to_rad, Rotor, RotorDynError};
use nalgebra::{DMatrix, DVector};
use serde_json::{json, Map, Value};
use std::path::Path;

/// The model file if it is a ROSS rotor (judged by its content: tables `ShaftElement_…`).
pub fn ross_model(path: Option<&Path>) -> Option<&Path> {
    let path = path?;
    let text = std::fs::read_to_string(path).ok()?;
    ross_file::looks_like_ross(&text).then_some(path)
}

fn to_cli(e: RotorDynError) -> CliError {
    match e {
        RotorDynError::Solver(m) => CliError::Failure(m),
        other => input(other.to_string()),
    }
}

/// Loads a ROSS rotor, errors naming the file.
pub fn load(path: &Path) -> Result<Rotor, CliError> {
    ross_file::read(path).map_err(to_cli)
}

fn check_speed(flag: &str, rpm: f64) -> Result<(), CliError> {
    if !rpm.is_finite() || rpm < 0.0 {
        return Err(input(format!("{flag} {rpm}: speed must be a finite number of rpm ≥ 0")));
    }
    Ok(())
}

/// `simulate --model ROSS-FILE [--speed RPM] --modes N`: damped modes at one speed.
pub fn simulate(path: &Path, speed_rpm: Option<f64>, modes: usize, json_out: bool) -> Result<(), CliError> {
    let rotor = load(path)?;
    let rpm = speed_rpm.unwrap_or(0.0);
    check_speed("--speed", rpm)?;
    if modes == 0 || modes > rotor.dofs() {
        return Err(input(format!("--modes {modes}: must be between 1 and {} for this rotor", rotor.dofs())));
    }
    let all = rotor.lowest_modes(rpm_to_rad(rpm), modes).map_err(to_cli)?;
    if modes > all.len() {
        return Err(input(format!(
            "--modes {modes}: must be between 1 and {} (the oscillating modes of this rotor at {rpm} rpm)",
            all.len()
        )));
    }
    let shown = &all[..modes];
    if json_out {
        let out = json!({
            "model": path.display().to_string(),
            "speed_rpm": rpm,
            "frequencies_hz": shown.iter().map(|m| m.frequency_hz()).collect::<Vec<_>>(),
            "natural_frequencies_hz": shown.iter().map(|m| m.natural_frequency_hz()).collect::<Vec<_>>(),
            "whirl": shown.iter().map(|m| m.whirl.name()).collect::<Vec<_>>(),
            "damping_ratio": shown.iter().map(|m| m.damping_ratio()).collect::<Vec<_>>(),
            "log_dec": shown.iter().map(|m| m.log_dec()).collect::<Vec<_>>(),
        });
        crate::output::emit_json(out);
    } else {
        println!("{}: {} DOF two-plane rotor at {rpm} rpm", path.display(), rotor.dofs());
        println!(
            "{:>6}{:>16}{:>16}{:>12}{:>12}{:>10}",
            "mode", "damped [Hz]", "natural [Hz]", "ζ", "log dec", "whirl"
        );
        for (i, m) in shown.iter().enumerate() {
            println!(
                "{:>6}{:>16.6}{:>16.6}{:>12.5}{:>12.5}{:>10}",
                i + 1,
                m.frequency_hz(),
                m.natural_frequency_hz(),
                m.damping_ratio(),
                m.log_dec(),
                m.whirl.name()
            );
        }
    }
    Ok(())
}

/// The fit's quality judged by core's verdict rules, as for the planar model: the run-up's
/// frequencies and residuals put in a [`Linearisation`] (eigenvalues λ = ω², Jacobians in the
/// physical units of the parameters).
fn fit_quality(id: &Identification, points: &[RunupPoint], values: &[f64]) -> FitQuality {
    let has_std = points.iter().all(|p| p.std_hz.is_some());
    let m = points.len();
    let omega = |f: f64| 2.0 * std::f64::consts::PI * f;
    // Residual measured − model in σ, or relative without std (the planar `relative` residual).
    let sigma = |i: usize| points[i].std_hz.unwrap_or(points[i].frequency_hz);
    // d f/d p = (d f/d ln s)/p in Hz per N/m (N·s/m); dλ/dp = 2ω·2π d f/d p.
    let df_dp = DMatrix::from_fn(m, values.len(), |i, j| id.jacobian[(i, j)] / values[j]);
    let lin = Linearisation {
        parameters: values.to_vec(),
        paired_modes: points.iter().map(|p| p.mode - 1).collect(),
        model_eigenvalues: DVector::from_iterator(m, id.model_hz.iter().map(|&f| omega(f).powi(2))),
        measured_eigenvalues: DVector::from_iterator(m, points.iter().map(|p| omega(p.frequency_hz).powi(2))),
        eigenvalue_jacobian: DMatrix::from_fn(m, values.len(), |i, j| {
            2.0 * omega(id.model_hz[i]) * 2.0 * std::f64::consts::PI * df_dp[(i, j)]
        }),
        frequencies_hz: id.model_hz.clone(),
        measured_hz: points.iter().map(|p| p.frequency_hz).collect(),
        residual: DVector::from_fn(m, |i, _| (points[i].frequency_hz - id.model_hz[i]) / sigma(i)),
        jacobian: DMatrix::from_fn(m, values.len(), |i, j| df_dp[(i, j)] / sigma(i)),
        has_std,
    };
    judge(&lin, values.len())
}

/// `estimate --model ROSS-FILE --measured RUNUP.csv [--parameters kxx,kyy,…]`: bearing
/// coefficients from a run-up (default kxx and kyy of every bearing).
pub fn estimate(
    path: &Path,
    measured: &Path,
    selection: Option<&str>,
    max_iterations: usize,
    json_out: bool,
) -> Result<u8, CliError> {
    let rotor = load(path)?;
    let points = read_runup(measured).map_err(to_cli)?;
    let chosen: Vec<&str> = match selection {
        Some(list) => list.split(',').map(str::trim).filter(|s| !s.is_empty()).collect(),
        None => DEFAULT_COEFFICIENTS.to_vec(),
    };
    let params = bearing_parameters(&rotor, &chosen).map_err(|e| input(format!("--parameters: {e}")))?;
    if params.is_empty() {
        return Err(input(format!("{}: the rotor has no bearings to estimate", path.display())));
    }
    let initial = vec![1.0; params.len()];
    let id = identify(&rotor, &params, &points, &initial, max_iterations).map_err(to_cli)?;
    // Report each coefficient at the lowest measured speed (constant bearings: their value).
    let w0 = rpm_to_rad(points.iter().map(|p| p.speed_rpm).fold(f64::INFINITY, f64::min));
    let nominal: Vec<f64> = params.iter().map(|p| p.nominal(&rotor, w0)).collect();
    let value: Vec<f64> = nominal.iter().zip(&id.scales).map(|(k, s)| k * s).collect();
    let names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
    let obj = |values: Vec<Value>| -> Map<String, Value> { names.iter().cloned().zip(values).collect() };
    // 95 % intervals, log-normal (the estimate is linearised in ln k); ordered low, high also
    // for a negative (cross-coupled) coefficient.
    let intervals: Option<Vec<[f64; 2]>> = id.ln_std.as_ref().map(|sd| {
        value
            .iter()
            .zip(sd)
            .map(|(v, s)| {
                let (a, b) = (v * (-1.96 * s).exp(), v * (1.96 * s).exp());
                [a.min(b), a.max(b)]
            })
            .collect()
    });
    let quality = fit_quality(&id, &points, &value);
    let acceptable = id.converged && quality.verdict != FitVerdict::Poor;
    let verdict = if !id.converged {
        "not-converged"
    } else if quality.verdict == FitVerdict::Poor {
        "poor-fit"
    } else if quality.verdict == FitVerdict::NotJudged {
        "converged (fit quality not judged: no std)"
    } else {
        "converged"
    };
    let status = |i: usize| -> String {
        match &intervals {
            _ if !id.converged => "(not computed: the run did not converge)".into(),
            Some(iv) => format!("[{:.4e}, {:.4e}]", iv[i][0], iv[i][1]),
            None if !id.identifiable => {
                "not identifiable: the frequencies fix only combinations of the parameters".into()
            }
            None => "(no std given)".into(),
        }
    };
    let disagreeing: Vec<Value> = quality
        .disagreeing
        .iter()
        .map(|&k| json!({"speed_rpm": points[k].speed_rpm, "mode": points[k].mode}))
        .collect();
    let dof = quality.dof;
    if json_out {
        let mut out = json!({
            "model": path.display().to_string(),
            "converged": id.converged,
            "acceptable": acceptable,
            "verdict": verdict,
            "fit_quality": quality.verdict.label(),
            "chi2": quality.chi2,
            "dof": dof,
            "p_value": quality.p_value,
            "relative_rms_residual": quality.relative_rms,
            "disagreeing_modes": disagreeing,
            "termination": id.reason,
            "iterations": id.iterations,
            "evaluations": id.evaluations,
            "reference_speed_rpm": w0 * 30.0 / std::f64::consts::PI,
            "initial": obj(nominal.iter().map(|&v| json!(v)).collect()),
            "parameters": obj(value.iter().map(|&v| json!(v)).collect()),
            "parameter_status": obj((0..params.len()).map(|i| json!(status(i))).collect()),
            "scales": obj(id.scales.iter().map(|&v| json!(v)).collect()),
            "cost": id.cost,
            "identifiable": id.identifiable,
            "points": points.iter().enumerate().map(|(i, p)| json!({
                "speed_rpm": p.speed_rpm,
                "mode": p.mode,
                "measured_hz": p.frequency_hz,
                "model_hz": id.model_hz[i],
                "model_whirl": id.model_whirl[i].name(),
                "measured_whirl": p.whirl.map(|w| w.name()),
            })).collect::<Vec<_>>(),
        });
        if let (Some(iv), Some(sd)) = (&intervals, &id.ln_std) {
            out["intervals"] = Value::Object(obj(iv.iter().map(|i| json!(i)).collect()));
            out["standard_deviations_ln"] = Value::Object(obj(sd.iter().map(|&s| json!(s)).collect()));
        }
        crate::output::emit_json(out);
    } else {
        println!(
            "{}: {} bearing coefficients from {} run-up frequencies: {} after {} iterations; verdict: {verdict}",
            path.display(),
            params.len(),
            points.len(),
            if id.converged { "converged" } else { "NOT converged" },
            id.iterations
        );
        println!("{:<28}{:>16}{:>16}{:>32}", "parameter", "initial", "estimate", "95% interval / status");
        for i in 0..params.len() {
            println!("{:<28}{:>16.4e}{:>16.6e}{:>32}", names[i], nominal[i], value[i], status(i));
        }
        println!(
            "{:>10}{:>6}{:>16}{:>16}{:>12}{:>10}",
            "rpm", "mode", "measured [Hz]", "model [Hz]", "diff [Hz]", "whirl"
        );
        for (i, p) in points.iter().enumerate() {
            println!(
                "{:>10.1}{:>6}{:>16.6}{:>16.6}{:>12.2e}{:>10}",
                p.speed_rpm,
                p.mode,
                p.frequency_hz,
                id.model_hz[i],
                id.model_hz[i] - p.frequency_hz,
                id.model_whirl[i].name()
            );
        }
        if let (Some(chi2), Some(p)) = (quality.chi2, quality.p_value) {
            println!("chi² = {chi2:.4} with {dof} degrees of freedom, p = {p:.3}");
        }
        if !disagreeing.is_empty() {
            println!("disagreeing by more than 3σ (rpm, mode): {}", Value::Array(disagreeing.clone()));
        }
        if !id.identifiable {
            println!(
                "not identifiable: the frequencies do not determine every parameter separately \
                 (an isotropic rotor's kxx and kyy act alike); no intervals"
            );
        }
    }
    Ok(if acceptable { EXIT_OK } else { EXIT_NOT_CONVERGED })
}
