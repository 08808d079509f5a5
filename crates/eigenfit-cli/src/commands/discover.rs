//! `eigenfit discover`: find where model and measurement disagree, name the missing effect, add it.

use crate::error::{CliError, EXIT_NOT_CONVERGED, EXIT_OK};
use crate::output::write_atomically;
use crate::plot;
use crate::plot::discovery::DiscoveryPlot;
use crate::progress::Bars;
use crate::source::ModelArgs;
use clap::Args;
use eigenfit_core::discovery::DiscoveryReport;
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::discovery::RotorDiscovery;
use eigenfit_workflow::discover::{self, Discovery, Refitted};
use eigenfit_workflow::Named;
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
    /// Most model evaluations (eigen-solves) the data check and the whole search may spend
    /// together; when it runs out the search stops with what it has and the run ends with exit
    /// code 3 (as `estimate`'s `--budget`).
    #[arg(long, value_name = "N", default_value_t = eigenfit_core::discovery::DEFAULT_EVALUATIONS)]
    pub budget: usize,
    /// The strategy of the calibration and of every candidate's refit, by registered name with
    /// settings after colons (as `estimate --strategy`); default: damped least squares. Not for
    /// ROSS run-ups.
    #[arg(long, value_name = "STRATEGY")]
    pub refit: Option<String>,
    /// Write the augmented model (calibrated stiffnesses + the named effect) to this TOML file.
    #[arg(long, value_name = "FILE.toml")]
    pub write_model: Option<PathBuf>,
    /// Write the before/after residual plot (discovery.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
    /// `--report FILE.html`.
    #[command(flatten)]
    pub html: crate::report::HtmlArgs,
}

/// Runs `discover`; returns the exit code: 0 when the data are explained (by the noise, or after
/// the named effects), 3 when a significant disagreement stays unexplained or the budget ran out.
pub fn run(args: &DiscoverArgs) -> Result<u8, CliError> {
    // Checked before anything is read.
    let refit = eigenfit_workflow::estimate::refit_choice(args.refit.as_deref())?;
    // Two-plane rotors saved by ROSS, against a run-up CSV: the rotordynamics workflow.
    if let Some(path) = eigenfit_workflow::rotordynamics::ross_model(args.model.model.as_deref()) {
        if args.write_model.is_some() || args.plot.is_some() || args.refit.is_some() {
            return Err(crate::error::input(
                "--write-model, --plot and --refit are not available for ROSS rotors (the report names the effects)",
            ));
        }
        args.html.check()?;
        let html = args.html.html.as_ref().map(|_| html_inputs(args));
        let report =
            eigenfit_workflow::rotordynamics::discover(path, &args.measured, args.assumed_std, args.budget)?;
        // The rule of every discover, decided once in the workflow's report (`explained`): 0 when
        // the data are explained, 3 when not or the budget ran out (the report is still printed).
        let code = if report.discovery.explained { EXIT_OK } else { EXIT_NOT_CONVERGED };
        crate::error::set_exit_on_closed_pipe(code);
        crate::output::report(args.report.json, &report, crate::rotordynamics::print_discovery);
        if let (Some(path), Some(mut html)) = (&args.html.html, html) {
            let names: Vec<String> =
                report.discovery.calibrated_parameters.iter().map(|(n, _)| n.clone()).collect();
            let units = crate::report::estimate::units(
                &report.discovery,
                &names,
                crate::report::estimate::ross_coefficient_unit,
            );
            crate::report::discover::fill(&mut html, &report.discovery, &units, None);
            html.write_after(path, args.report.json);
        }
        return Ok(code);
    }
    // Every output is checked writable before the search.
    if let Some(path) = &args.write_model {
        crate::output::check_writable(path, "--write-model")?;
    }
    if let Some(dir) = &args.plot {
        crate::output::check_writable_dir(dir, "--plot")?;
    }
    args.html.check()?;
    let html = args.html.html.as_ref().map(|_| html_inputs(args));
    let (model, label) = args.model.load_any()?;
    let solver = args.model.solver()?;
    let mut notes = Vec::new();
    let found = discover::run(
        &label,
        &model,
        solver.as_ref(),
        &args.measured,
        args.assumed_std,
        args.budget,
        refit,
        &mut notes,
        &mut Bars::new(args.report.quiet),
    );
    crate::commands::simulate::print_notes(&notes);
    let Discovery { found, mut report } = found?;
    let code = if report.explained { EXIT_OK } else { EXIT_NOT_CONVERGED };
    crate::error::set_exit_on_closed_pipe(code);
    if let Some(path) = &args.write_model {
        let text = discover::augmented_model_toml(&found, &model)?;
        // A write that fails after the search says what was lost; the exit code stays its own.
        match write_atomically(path, text.as_bytes()) {
            Ok(()) => report.written.push(path.display().to_string()),
            Err(e) => crate::output::report_lost("the augmented model", &e),
        }
    }
    if let Some(dir) = &args.plot {
        let figure = DiscoveryPlot::from_report(&label, &found.report);
        match plot::write(&figure, dir, "discovery") {
            Ok(w) => report.written.extend(plot::names(&w)),
            Err(e) => crate::output::report_lost("the discovery plot", &e),
        }
    }
    crate::output::report(args.report.json, &report, |report| {
        let names: Vec<String> = model.parameters().iter().map(|p| p.name.clone()).collect();
        let units: Vec<String> = model.parameters().iter().map(|p| p.unit.clone()).collect();
        print_report(&found, report.refitted_parameters.as_ref(), &names, &units, &label);
        for w in &report.written {
            println!("wrote {w}");
        }
    });
    if let (Some(path), Some(mut html)) = (&args.html.html, html) {
        let declared: Vec<String> = model.parameters().iter().map(|p| p.unit.clone()).collect();
        let names: Vec<String> = report.calibrated_parameters.iter().map(|(n, _)| n.clone()).collect();
        let units = crate::report::estimate::units(&report, &names, |n| {
            names.iter().position(|m| m == n).and_then(|i| declared.get(i).cloned()).unwrap_or_default()
        });
        let figure = DiscoveryPlot::from_report(&label, &found.report);
        crate::report::discover::fill(&mut html, &report, &units, Some(&figure));
        html.write_after(path, args.report.json);
    }
    Ok(code)
}

/// The report's page with the inputs recorded.
fn html_inputs(args: &DiscoverArgs) -> crate::report::Report {
    let mut html = crate::report::Report::new("discover", "discover");
    html.model_source(&args.model);
    html.input("measured data", &args.measured);
    html
}

fn print_report(
    found: &RotorDiscovery,
    refitted: Option<&Named<Refitted>>,
    names: &[String],
    units: &[String],
    label: &str,
) {
    let r: &DiscoveryReport = &found.report;
    println!("{label}: calibrated the nominal parameters:");
    for ((n, v), u) in names.iter().zip(&r.base_parameters).zip(units) {
        println!("  {n} = {v:.6e} {u}");
    }
    crate::output::print_misfit(&r.before);
    let flagged: Vec<String> = r
        .modes
        .iter()
        .filter(|m| m.normalised_before().abs() > 2.0)
        .map(|m| format!("{} ({:+.1}σ)", m.mode + 1, m.normalised_before()))
        .collect();
    if !flagged.is_empty() {
        println!("modes off by more than 2σ: {}", flagged.join(", "));
    }
    match (found.effects.is_empty(), r.before.significant) {
        (true, false) => println!("no significant disagreement: nothing added."),
        // Cut short, the search has not shown that nothing explains the data.
        (true, true) if r.budget_exhausted => {
            println!("no candidate effect confirmed before the budget ran out.");
            if let Some(best) = r.fits.iter().find(|f| f.plausible) {
                println!(
                    "  best partial explanation so far: {} (χ² {:.2} → {:.2})",
                    best.label, r.before.chi2, best.chi2
                );
            }
        }
        (true, true) if r.fits.is_empty() && !r.untestable.is_empty() => print_untestable(r),
        (true, true) => {
            println!(
                "no candidate effect, alone or with others, explains the disagreement down to the noise."
            );
            if let Some(best) = r.fits.iter().find(|f| f.plausible) {
                println!(
                    "  best partial explanation: {} (χ² {:.2} → {:.2})",
                    best.label, r.before.chi2, best.chi2
                );
            }
        }
        // Also without an overall significant misfit: the refined mesh is tested on its own.
        (false, _) => {
            let title = if found.effects.len() == 1 { "missing effect" } else { "missing effects" };
            println!("{title}:");
            for e in &found.effects {
                let value = e.value.map_or("on".to_string(), |v| format!("{v:.4e} {}", e.unit));
                let interval =
                    e.interval.map_or(String::new(), |iv| format!(", 95% [{:.3e}, {:.3e}]", iv[0], iv[1]));
                println!("  {} = {value}{interval} (ΔAICc {:.2})", e.label, e.delta_aicc);
                for c in &e.companions {
                    let iv = c
                        .interval
                        .map_or(String::new(), |iv| format!(", 95% [{:.3e}, {:.3e}]", iv[0], iv[1]));
                    println!("    with {} = {:.4e} {}{iv}", c.name, c.value, c.unit);
                }
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
                r.selected.as_ref().map_or((r.before.chi2, r.before.aicc), |s| (s.chi2, s.aicc));
            println!(
                "  evidence: χ² {:.2} → {:.2}, AICc {:.2} → {:.2}, RMS residual {:.4} → {:.4} Hz",
                r.before.chi2, chi2, r.before.aicc, aicc, r.rms_before_hz, r.rms_after_hz
            );
            if let Some(rows) = refitted {
                println!("  the model's parameters refitted with the effect:");
                for ((n, v), u) in rows.iter().zip(units) {
                    let interval = v
                        .interval
                        .map_or(String::new(), |iv| format!(", 95% [{:.3e}, {:.3e}]", iv[0], iv[1]));
                    println!("    {n} = {:.6e} {u}{interval}", v.value);
                }
            }
            if let Some(u) = &r.runner_up {
                println!("  runner-up to the first effect: {} (AICc {:.2} on its own)", u.label, u.aicc);
            }
        }
    }
    if r.spending.refits_skipped > 0 && !r.budget_exhausted {
        println!(
            "{} refit(s) of screened candidates left out to keep the budget for confirming the leader; raise it with --budget to try them",
            r.spending.refits_skipped
        );
    }
    // Said above already when nothing could be tested at all.
    let said = found.effects.is_empty() && r.fits.is_empty();
    if !r.untestable.is_empty() && !said {
        print_untestable(r);
    }
    if r.budget_exhausted {
        println!(
            "the evaluation budget ({} model evaluations) ran out: the search stopped with what it had, effects it had not reached were not tried; raise it with --budget",
            r.evaluations
        );
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

/// The candidates that could not be tested, and why.
fn print_untestable(r: &DiscoveryReport) {
    let Some(first) = r.untestable.first() else { return };
    let labels: Vec<&str> = r.untestable.iter().map(|u| u.place.label.as_str()).collect();
    println!(
        "cannot test {} candidate effect(s) ({}): with one of them the fit would have {} parameters for {} measured modes, \
         no degree of freedom left, so it would fit exactly whatever the truth; measure more modes (or hold a parameter fixed)",
        labels.len(),
        labels.join(", "),
        first.parameters,
        first.modes
    );
}
