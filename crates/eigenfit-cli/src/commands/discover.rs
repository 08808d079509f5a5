//! `eigenfit discover`: find where model and measurement disagree, name the missing effect, add it.

use crate::error::{input, CliError};
use crate::output::write_atomically;
use crate::plot::discovery::DiscoveryPlot;
use crate::source::ModelArgs;
use crate::{measured, plot, progress};
use clap::Args;
use eigenfit_core::discovery::{discover, DiscoveryOptions, DiscoveryReport, Fit};
use eigenfit_core::StructuralModel;
use eigenfit_rotor::EffectSpec;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Arguments of `discover`.
#[derive(Debug, Args)]
pub struct DiscoverArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Measured frequencies: CSV `mode,frequency_hz[,std_hz]` (6–8 modes typical).
    #[arg(long, value_name = "FILE.csv")]
    pub measured: PathBuf,
    /// Relative frequency standard deviation assumed where the file gives none.
    #[arg(long, default_value_t = 1e-3)]
    pub assumed_std: f64,
    /// Write the augmented model (calibrated stiffnesses + the named effect) to this TOML file.
    #[arg(long, value_name = "FILE.toml")]
    pub write_model: Option<PathBuf>,
    /// Write the before/after residual plot (discovery.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// No progress indicator.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
}

/// Runs `discover`.
pub fn run(args: &DiscoverArgs) -> Result<(), CliError> {
    let (model, label) = args.model.load_any()?;
    let rotor = &model;
    let solver = args.model.solver()?;
    let data = measured::read(&args.measured)?;
    if !(args.assumed_std.is_finite() && args.assumed_std > 0.0) {
        return Err(input(format!("--assumed-std {}: must be a positive number", args.assumed_std)));
    }
    let options = DiscoveryOptions { assumed_relative_std: args.assumed_std, ..Default::default() };
    let candidates = rotor.candidates();
    let pb = progress::spinner("discovering: calibrate, detect, screen and refit candidates", args.quiet);
    let report = discover(
        &rotor,
        &solver.as_ref(),
        &data,
        &candidates,
        &rotor.parameters().nominal_values(),
        &options,
    );
    pb.finish_and_clear();
    let report = report.map_err(|e| input(format!("{}: {e}", args.measured.display())))?;
    let names: Vec<String> = rotor.parameters().iter().map(|p| p.name.clone()).collect();
    let mut written = Vec::new();
    if let Some(path) = &args.write_model {
        let nb = names.len();
        let fitted = report.selected.as_ref().map_or(&report.base_parameters[..], |s| &s.parameters[..nb]);
        let mut augmented = rotor
            .rotor("--write-model")?
            .with_stiffnesses(fitted)
            .map_err(|e| CliError::Failure(e.to_string()))?;
        if let Some(sel) = &report.selected {
            let effect = EffectSpec::new(sel.kind.clone(), sel.location, sel.value.unwrap_or(1.0));
            augmented = augmented.with_effect(effect).map_err(|e| CliError::Failure(e.to_string()))?;
        }
        let text = augmented.to_toml_string().map_err(|e| CliError::Failure(e.to_string()))?;
        write_atomically(path, text.as_bytes())?;
        written.push(path.display().to_string());
    }
    if let Some(dir) = &args.plot {
        let figure = DiscoveryPlot::from_report(&label, &report);
        written.extend(plot::names(&plot::write(&figure, dir, "discovery")?));
    }
    if args.json {
        crate::output::emit_json(report_json(&report, &names, &label, &written));
    } else {
        let units: Vec<String> = rotor.parameters().iter().map(|p| p.unit.clone()).collect();
        print_report(&report, &names, &units, &label);
        for w in written {
            println!("wrote {w}");
        }
    }
    Ok(())
}

fn fit_json(f: &Fit) -> Value {
    json!({"kind": f.kind, "location": f.location, "value": f.value, "unit": f.unit, "interval": f.interval,
           "chi2": f.chi2, "aicc": f.aicc, "plausible": f.plausible})
}

fn report_json(r: &DiscoveryReport, names: &[String], label: &str, written: &[String]) -> Value {
    let missing = r.selected.as_ref().map(|s| {
        json!({"kind": s.kind, "location": s.location, "value": s.value.unwrap_or(1.0), "unit": s.unit,
               "interval": s.interval, "delta_aicc": r.aicc_before - s.aicc})
    });
    let base: serde_json::Map<String, Value> =
        names.iter().cloned().zip(r.base_parameters.iter().map(|&v| json!(v))).collect();
    json!({
        "model": label,
        "disagreement_significant": r.disagreement_significant,
        "missing_effect": missing,
        "rms_residual_before_hz": r.rms_before_hz,
        "rms_residual_after_hz": r.rms_after_hz,
        "chi2_before": r.chi2_before,
        "dof_before": r.dof_before,
        "p_value": r.p_value,
        "calibrated_parameters": base,
        "runner_up": r.runner_up.as_ref().map(fit_json),
        "candidates_refitted": r.fits.iter().map(fit_json).collect::<Vec<_>>(),
        "modes": r.modes.iter().map(|m| json!({"mode": m.mode + 1, "measured_hz": m.measured_hz, "std_hz": m.std_hz,
            "before_hz": m.before_hz, "after_hz": m.after_hz})).collect::<Vec<_>>(),
        "written": written,
    })
}

fn print_report(r: &DiscoveryReport, names: &[String], units: &[String], label: &str) {
    println!("{label}: calibrated the nominal parameters:");
    for ((n, v), u) in names.iter().zip(&r.base_parameters).zip(units) {
        println!("  {n} = {v:.6e} {u}");
    }
    println!(
        "misfit: χ² = {:.2} on {} degrees of freedom, p = {:.3e} → {}",
        r.chi2_before,
        r.dof_before,
        r.p_value,
        if r.disagreement_significant {
            "significant: the model misses something"
        } else {
            "explained by the noise"
        }
    );
    let flagged: Vec<String> = r
        .modes
        .iter()
        .filter(|m| m.normalised_before().abs() > 2.0)
        .map(|m| format!("{} ({:+.1}σ)", m.mode + 1, m.normalised_before()))
        .collect();
    if !flagged.is_empty() {
        println!("modes off by more than 2σ: {}", flagged.join(", "));
    }
    match (&r.selected, r.disagreement_significant) {
        (_, false) => println!("no significant disagreement: nothing added."),
        (None, true) => {
            println!("no single candidate effect explains the disagreement down to the noise.");
            if let Some(best) = r.fits.iter().find(|f| f.plausible) {
                println!(
                    "  best partial explanation: {} (χ² {:.2} → {:.2})",
                    best.label, r.chi2_before, best.chi2
                );
            }
        }
        (Some(s), true) => {
            let value = s.value.map_or("on".to_string(), |v| format!("{v:.4e} {}", s.unit));
            let interval =
                s.interval.map_or(String::new(), |iv| format!(", 95% [{:.3e}, {:.3e}]", iv[0], iv[1]));
            println!("missing effect: {} = {value}{interval}", s.label);
            println!(
                "  evidence: χ² {:.2} → {:.2}, AICc {:.2} → {:.2} (Δ = {:.2}), RMS residual {:.4} → {:.4} Hz",
                r.chi2_before,
                s.chi2,
                r.aicc_before,
                s.aicc,
                r.aicc_before - s.aicc,
                r.rms_before_hz,
                r.rms_after_hz
            );
            if let Some(u) = &r.runner_up {
                println!(
                    "  runner-up: {} (AICc {:.2}, Δ to the named effect {:.2})",
                    u.label,
                    u.aicc,
                    u.aicc - s.aicc
                );
            }
        }
    }
    println!(
        "{:>5}{:>14}{:>10}{:>14}{:>9}{:>14}{:>9}",
        "mode", "measured [Hz]", "σ [Hz]", "before [Hz]", "[σ]", "after [Hz]", "[σ]"
    );
    for m in &r.modes {
        println!(
            "{:>5}{:>14.4}{:>10.4}{:>14.4}{:>9.2}{:>14.4}{:>9.2}",
            m.mode + 1,
            m.measured_hz,
            m.std_hz,
            m.before_hz,
            m.normalised_before(),
            m.after_hz,
            m.normalised_after()
        );
    }
}
