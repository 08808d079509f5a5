//! `eigenfit campaign`: several test configurations estimated jointly (docs/test-data.md).

use crate::error::{CliError, EXIT_NOT_CONVERGED};
use crate::progress::Bars;
use clap::Args;
use eigenfit_workflow::campaign::{self, CampaignRequest};
use std::path::PathBuf;

/// Arguments of `campaign`.
#[derive(Debug, Args)]
pub struct CampaignArgs {
    /// Campaign file (TOML): `[[configuration]]` tables with `model`, `measured` and optionally
    /// `name`, `shapes`, `sensor_map`.
    #[arg(value_name = "CAMPAIGN.toml")]
    pub campaign: PathBuf,
    /// Update strategy: newton, p-step or damped (Levenberg–Marquardt; `levenberg-marquardt` is accepted too).
    #[arg(long, default_value = "damped")]
    pub strategy: String,
    /// Eigen-solver backend: banded (default) or dense.
    #[arg(long, default_value = "banded")]
    pub solver: String,
    /// Iteration limit.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// Most model evaluations (eigen-solves) the joint fit and its intervals may spend together;
    /// when it runs out the run ends with exit code 3 and says so (as `estimate`'s `--budget`).
    #[arg(long, value_name = "N", default_value_t = eigenfit_core::update::DEFAULT_EVALUATIONS)]
    pub budget: usize,
    /// Node matching, shape weight and MAC threshold.
    #[command(flatten)]
    pub shape: crate::testdata::ShapeArgs,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
    /// `--report FILE.html`.
    #[command(flatten)]
    pub html: crate::report::HtmlArgs,
}

/// Runs `campaign`; returns the exit code (3 when not converged or a mode is unpaired).
pub fn run(args: &CampaignArgs) -> Result<u8, CliError> {
    let request = CampaignRequest {
        campaign: args.campaign.clone(),
        strategy: args.strategy.clone(),
        solver: args.solver.clone(),
        max_iterations: args.max_iterations,
        budget: args.budget,
        shape: args.shape.options(),
    };
    args.html.check()?;
    // The inputs are hashed as they are read: the campaign file and the files it names.
    let html = args.html.html.as_ref().map(|_| html_inputs(&args.campaign));
    let report = campaign::run(&request, &mut Bars::new(args.report.quiet))?;
    crate::commands::simulate::print_notes(&report.file_notes);
    // estimate's rule: 0 only for an acceptable answer (a poor fit, a parameter on a limit, an
    // unpaired mode, the budget spent or no convergence is 3).
    let code = if report.verdict.is_answer() { 0 } else { EXIT_NOT_CONVERGED };
    crate::error::set_exit_on_closed_pipe(code);
    crate::output::report(args.report.json, &report, |report| {
        println!(
            "{}: {} configurations, {} strategy, {} after {} iterations",
            report.campaign,
            report.configurations.len(),
            report.strategy,
            report.outcome.termination,
            report.outcome.iterations
        );
        println!("{:<24}{:>16}{:>16}{:>34}", "parameter", "initial", "estimate", "95% interval");
        for (i, ((name, initial), (_, value))) in
            report.initial.iter().zip(report.parameters.iter()).enumerate()
        {
            let n = format!("{name}{}", eigenfit_core::model::bracketed(&report.units.0[i].1));
            let iv = report.intervals.as_ref().map_or("-".to_string(), |u| {
                let iv = u.0[i].1;
                format!("[{:.4e}, {:.4e}]", iv[0], iv[1])
            });
            println!("{n:<24}{initial:>16.4e}{value:>16.6e}{iv:>34}");
        }
        for c in &report.configurations {
            println!("{}:", c.name);
            for (k, (m, f)) in c.frequencies.measured_hz.iter().zip(&c.frequencies.frequencies_hz).enumerate()
            {
                let mac_text = c
                    .mac_pairing
                    .as_ref()
                    .map_or(String::new(), |p| format!("  MAC {:.4} with model mode {}", p[k].2, p[k].1));
                println!(
                    "  mode {:>2}: measured {m:>12.6} Hz, model {f:>12.6} Hz{mac_text}",
                    c.mode_numbers[k]
                );
            }
            c.notes.iter().for_each(|n| eprintln!("note: {}: {n}", c.name));
        }
        let quality = &report.quality;
        match quality.p_value {
            Some(pv) => println!(
                "fit quality: chi2 = {:.4} with {} degrees of freedom, p = {pv:.3e}",
                report.chi2, quality.dof
            ),
            None if report.has_std => {
                println!("fit quality: chi2 = {:.4} (no degree of freedom left)", report.chi2)
            }
            None => {}
        }
        if !report.at_limit.is_empty() {
            println!("on a limit at the estimate: {}", report.at_limit.join(", "));
        }
        println!(
            "verdict: {}{}",
            report.verdict.verdict,
            if report.verdict.acceptable { "" } else { " — not an acceptable answer (exit code 3)" }
        );
        if let Some(s) = report.scatter.filter(|_| !report.has_std) {
            println!("intervals from the residual scatter (no std in the data): sigma_hat = {s:.3e}");
        }
        if report.budget.exhausted {
            println!(
                "the evaluation budget ({} model evaluations) ran out: results are incomplete; raise it with --budget",
                report.budget.limit
            );
        }
    });
    if let (Some(path), Some(mut html)) = (&args.html.html, html) {
        let units: Vec<Option<String>> =
            report.units.iter().map(|(_, u)| Some(u.clone()).filter(|u| !u.is_empty())).collect();
        crate::report::campaign::fill(&mut html, &report, &units);
        html.write_after(path, args.report.json);
    }
    Ok(code)
}

/// The report's page with the inputs recorded: the campaign file and each configuration's model
/// and data files (a campaign file that cannot be read records itself only; the run says why).
fn html_inputs(path: &std::path::Path) -> crate::report::Report {
    let mut html = crate::report::Report::new("campaign", "campaign");
    html.input("campaign file", path);
    if let Ok(c) = eigenfit_rotor::campaign::Campaign::from_toml_file(path) {
        for (k, conf) in c.configurations.iter().enumerate() {
            let name = conf.name.clone().unwrap_or_else(|| format!("configuration {}", k + 1));
            html.input(&format!("{name}: model"), &conf.model);
            html.input(&format!("{name}: measured data"), &conf.measured);
            if let Some(p) = &conf.shapes {
                html.input(&format!("{name}: measured shapes"), p);
            }
            if let Some(p) = &conf.sensor_map {
                html.input(&format!("{name}: sensor map"), p);
            }
        }
    }
    html
}
