//! `eigenfit discover`: find where model and measurement disagree, name the missing effect, add it.

use crate::any_model::AnyModel;
use crate::error::{input, CliError};
use crate::output::write_atomically;
use crate::plot::discovery::DiscoveryPlot;
use crate::source::ModelArgs;
use crate::{measured, plot, progress};
use clap::Args;
use eigenfit_core::discovery::{discover, Alternative, DiscoveryOptions, DiscoveryReport, Fit, NamedEffect};
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::discovery::{discover_rotor, RotorDiscovery};
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
    let pb = progress::spinner("discovering: calibrate, detect, screen and refit candidates", args.quiet);
    let found = match &model {
        AnyModel::Rotor(r) => discover_rotor(r, &solver.as_ref(), &data, &r.nominal_stiffnesses(), &options),
        // A matrices model has no mesh to refine: the generic workflow over its [[candidate]]s.
        AnyModel::Matrices(m) => {
            discover(m, &solver.as_ref(), &data, &m.candidates(), &m.parameters().nominal_values(), &options)
                .map(|report| RotorDiscovery { effects: report.effects.clone(), report, mesh_factor: 1 })
        }
    };
    pb.finish_and_clear();
    let found = found.map_err(|e| input(format!("{}: {e}", args.measured.display())))?;
    let report = &found.report;
    let names: Vec<String> = rotor.parameters().iter().map(|p| p.name.clone()).collect();
    let mut written = Vec::new();
    if let Some(path) = &args.write_model {
        let augmented = found
            .augmented_model(model.rotor("--write-model")?)
            .map_err(|e| CliError::Failure(e.to_string()))?;
        let text = augmented.to_toml_string().map_err(|e| CliError::Failure(e.to_string()))?;
        write_atomically(path, text.as_bytes())?;
        written.push(path.display().to_string());
    }
    if let Some(dir) = &args.plot {
        let figure = DiscoveryPlot::from_report(&label, report);
        written.extend(plot::names(&plot::write(&figure, dir, "discovery")?));
    }
    if args.json {
        crate::output::emit_json(report_json(&found, &names, &label, &written));
    } else {
        let units: Vec<String> = rotor.parameters().iter().map(|p| p.unit.clone()).collect();
        print_report(&found, &names, &units, &label);
        for w in written {
            println!("wrote {w}");
        }
    }
    Ok(())
}

fn fit_json(f: &Fit) -> Value {
    let mut v = json!({"kind": f.kind, "location": f.location, "value": f.value, "unit": f.unit, "interval": f.interval,
           "chi2": f.chi2, "aicc": f.aicc, "plausible": f.plausible});
    place(&mut v, f.position_m, f.elements);
    v
}

/// Adds `position_m` and `elements` where the effect has them.
fn place(v: &mut Value, position_m: Option<f64>, elements: Option<[usize; 2]>) {
    if let Some(x) = position_m {
        v["position_m"] = json!(x);
    }
    if let Some(e) = elements {
        v["elements"] = json!(e);
    }
}

fn alternative_json(a: &Alternative) -> Value {
    let mut v = json!({"kind": a.kind, "location": a.location, "value": a.value, "unit": a.unit,
                       "delta_aicc": a.delta_aicc});
    place(&mut v, a.position_m, a.elements);
    v
}

fn effect_json(e: &NamedEffect) -> Value {
    let mut v = json!({"kind": e.kind, "location": e.location, "value": e.value.unwrap_or(1.0), "unit": e.unit,
        "interval": e.interval, "delta_aicc": e.delta_aicc,
        "ambiguous_with": e.ambiguous_with.iter().map(alternative_json).collect::<Vec<_>>()});
    place(&mut v, e.position_m, e.elements);
    v
}

fn report_json(found: &RotorDiscovery, names: &[String], label: &str, written: &[String]) -> Value {
    let r = &found.report;
    let missing = found.effects.first().map(effect_json);
    let base: serde_json::Map<String, Value> =
        names.iter().cloned().zip(r.base_parameters.iter().map(|&v| json!(v))).collect();
    json!({
        "model": label,
        "disagreement_significant": r.disagreement_significant,
        "missing_effect": missing,
        "missing_effects": found.effects.iter().map(effect_json).collect::<Vec<_>>(),
        "mesh_refinement": found.mesh_factor,
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

fn print_report(found: &RotorDiscovery, names: &[String], units: &[String], label: &str) {
    let r: &DiscoveryReport = &found.report;
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
    match (found.effects.is_empty(), r.disagreement_significant) {
        (_, false) => println!("no significant disagreement: nothing added."),
        (true, true) => {
            println!(
                "no candidate effect, alone or with others, explains the disagreement down to the noise."
            );
            if let Some(best) = r.fits.iter().find(|f| f.plausible) {
                println!(
                    "  best partial explanation: {} (χ² {:.2} → {:.2})",
                    best.label, r.chi2_before, best.chi2
                );
            }
        }
        (false, true) => {
            let title = if found.effects.len() == 1 { "missing effect" } else { "missing effects" };
            println!("{title}:");
            for e in &found.effects {
                let value = e.value.map_or("on".to_string(), |v| format!("{v:.4e} {}", e.unit));
                let interval =
                    e.interval.map_or(String::new(), |iv| format!(", 95% [{:.3e}, {:.3e}]", iv[0], iv[1]));
                println!("  {} = {value}{interval} (ΔAICc {:.2})", e.label, e.delta_aicc);
                if e.kind == "mesh-refinement" {
                    println!("    the model's mesh is too coarse for this noise: refining it explains part of the gap");
                }
                for a in &e.ambiguous_with {
                    println!(
                        "    ambiguous with {} (ΔAICc {:+.2}): the data cannot tell them apart",
                        a.label, a.delta_aicc
                    );
                }
            }
            let (chi2, aicc) =
                r.selected.as_ref().map_or((r.chi2_before, r.aicc_before), |s| (s.chi2, s.aicc));
            println!(
                "  evidence: χ² {:.2} → {:.2}, AICc {:.2} → {:.2}, RMS residual {:.4} → {:.4} Hz",
                r.chi2_before, chi2, r.aicc_before, aicc, r.rms_before_hz, r.rms_after_hz
            );
            if let Some(u) = &r.runner_up {
                println!("  runner-up to the first effect: {} (AICc {:.2} on its own)", u.label, u.aicc);
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
