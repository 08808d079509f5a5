//! Two-plane rotors (files written by ROSS `Rotor.save`) in `simulate`, `estimate` and `discover`: the
//! tables of the rotordynamics workflow's reports.

use eigenfit_workflow::estimate::ParameterIdentifiability;
use eigenfit_workflow::rotordynamics::{RunupDiscoverReport, RunupEstimateReport, SpeedReport};

/// `simulate --model ROSS-FILE`: damped modes at one speed.
pub fn print_speed(r: &SpeedReport) {
    println!("{}: {} DOF two-plane rotor at {} rpm", r.model, r.dofs, r.speed_rpm);
    println!(
        "{:>6}{:>16}{:>16}{:>12}{:>12}{:>10}",
        "mode", "damped [Hz]", "natural [Hz]", "ζ", "log dec", "whirl"
    );
    for i in 0..r.frequencies_hz.len() {
        println!(
            "{:>6}{:>16.6}{:>16.6}{:>12.5}{:>12.5}{:>10}",
            i + 1,
            r.frequencies_hz[i],
            r.natural_frequencies_hz[i],
            r.damping_ratio[i],
            r.log_dec[i],
            r.whirl[i]
        );
    }
}

/// `estimate --model ROSS-FILE --measured RUNUP.csv`: the bearing coefficients, the verdict and
/// the points.
pub fn print_estimate(r: &RunupEstimateReport) {
    println!(
        "{}: {} bearing coefficients from {} run-up frequencies: {} after {} iterations; verdict: {}",
        r.model,
        r.values.parameters.0.len(),
        r.points.len(),
        if r.outcome.converged { "converged" } else { "NOT converged" },
        r.outcome.iterations,
        r.verdict.verdict
    );
    if r.refits > 0 {
        println!(
            "the fit from the file's bearings did not pass (χ² test; without std: not exact): {} more from screened starts, the best kept ({} evaluations in all)",
            r.refits, r.outcome.evaluations
        );
    }
    if !r.outcome.converged {
        println!("stopped: {}", r.outcome.termination.detail);
    }
    println!(
        "{:<28}{:>8}{:>16}{:>16}{:>32}",
        "parameter", "unit", "initial", "estimate", "95% interval / status"
    );
    let rows = r
        .values
        .initial
        .iter()
        .zip(r.values.parameters.iter())
        .zip(r.values.parameter_status.iter())
        .zip(r.units.iter());
    for ((((name, initial), (_, value)), (_, status)), (_, unit)) in rows {
        println!("{name:<28}{unit:>8}{initial:>16.4e}{value:>16.6e}{status:>32}");
    }
    println!(
        "{:>10}{:>6}{:>16}{:>16}{:>12}{:>10}",
        "rpm", "mode", "measured [Hz]", "model [Hz]", "diff [Hz]", "whirl"
    );
    for p in &r.points {
        println!(
            "{:>10.1}{:>6}{:>16.6}{:>16.6}{:>12.2e}{:>10}",
            p.speed_rpm,
            p.mode,
            p.measured_hz,
            p.model_hz,
            p.model_hz - p.measured_hz,
            p.model_whirl
        );
    }
    if let (Some(chi2), Some(p)) = (r.fit.chi2, r.fit.p_value) {
        println!("chi² = {chi2:.4} with {} degrees of freedom, p = {p:.3}", r.fit.dof);
    }
    if !r.fit.disagreeing_modes.is_empty() {
        let list: Vec<String> =
            r.fit.disagreeing_modes.iter().map(|d| format!("{} rpm mode {}", d.speed_rpm, d.mode)).collect();
        match r.fit.chi2 {
            Some(_) => println!("disagreeing by more than 3σ: {}", list.join(", ")),
            None => println!(
                "fit quality: POOR without std_hz: relative RMS residual {:.3e}, more than {} (no measured \
                 frequency is that far off); points off by more than that: {}",
                r.fit.relative_rms_residual,
                eigenfit_core::analysis::verdict::NO_STD_POOR_RELATIVE_RMS,
                list.join(", ")
            ),
        }
    }
    let undetermined: Vec<&str> = r
        .identifiable
        .iter()
        .flat_map(|m| m.iter())
        .filter(|(_, id)| !matches!(id, ParameterIdentifiability::Determined(true)))
        .map(|(n, _)| n.as_str())
        .collect();
    if !undetermined.is_empty() {
        println!(
            "not identifiable: {} (the frequencies do not determine every parameter separately, \
             e.g. a symmetric rotor's two bearings act alike)",
            undetermined.join(", ")
        );
    }
    crate::output::print_alternatives(&r.alternative_solutions, r.alternatives_sigma);
}

/// `discover --model ROSS-FILE --measured RUNUP.csv`: the calibration, the misfit test and the
/// named effects.
pub fn print_discovery(r: &RunupDiscoverReport) {
    let d = &r.discovery;
    println!("{}: calibrated the bearings (at {} rpm):", d.model, r.reference_speed_rpm);
    for (n, v) in d.calibrated_parameters.iter() {
        println!("  {n} = {v:.6e} {}", crate::report::estimate::ross_coefficient_unit(n));
    }
    crate::output::print_misfit(&d.before);
    if !d.before.significant {
        println!("no significant disagreement: nothing added.");
    } else if d.missing_effects.is_empty() {
        println!("no candidate effect, alone or with others, explains the disagreement down to the noise.");
    }
    for e in &d.missing_effects {
        let interval = e.interval.map_or(String::new(), |[a, b]| format!(" (95 %: {a:.4e} … {b:.4e})"));
        println!(
            "missing effect: {} at {} = {:.4e} {}{interval}, AICc gain {:.1}",
            e.kind,
            e.location.map_or("-".into(), |l| l.to_string()),
            e.value.unwrap_or(1.0),
            e.unit,
            e.delta_aicc
        );
    }
    println!(
        "RMS residual {:.4} Hz → {:.4} Hz; {} eigen-solve rounds",
        d.rms.rms_residual_before_hz, d.rms.rms_residual_after_hz, d.evaluations
    );
}
