//! Two-plane rotors (files written by ROSS `Rotor.save`) in `simulate` and `estimate`: the
//! tables of the rotordynamics workflow's reports.

use eigenfit_workflow::rotordynamics::{RunupEstimateReport, SpeedReport};

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
        r.parameters.0.len(),
        r.points.len(),
        if r.outcome.converged { "converged" } else { "NOT converged" },
        r.outcome.iterations,
        r.verdict
    );
    println!("{:<28}{:>16}{:>16}{:>32}", "parameter", "initial", "estimate", "95% interval / status");
    for (((name, initial), (_, value)), (_, status)) in
        r.initial.iter().zip(r.parameters.iter()).zip(r.parameter_status.iter())
    {
        println!("{name:<28}{initial:>16.4e}{value:>16.6e}{status:>32}");
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
        println!("disagreeing by more than 3σ: {}", list.join(", "));
    }
    if !r.identifiable {
        println!(
            "not identifiable: the frequencies do not determine every parameter separately \
             (an isotropic rotor's kxx and kyy act alike); no intervals"
        );
    }
}
