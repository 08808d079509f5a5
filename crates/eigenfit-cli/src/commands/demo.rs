//! `eigenfit demo`: the paper rotor end to end — Table 1 side by side, the estimation of Table 3
//! case 1 with all three strategies, a convergence map, and discovery of a hidden effect in a
//! built-in dataset — with a short report and every plot kind written to a folder. The
//! computations are `eigenfit_workflow::demo`.

use crate::commands::{compare, simulate};
use crate::error::{input, CliError};
use crate::plot;
use crate::plot::convergence::{Convergence, Run};
use crate::plot::discovery::DiscoveryPlot;
use crate::progress::Bars;
use clap::Args;
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::presets;
use eigenfit_workflow::compare::AT_TARGET;
use eigenfit_workflow::demo::{self, Demo, DemoReport, LABEL, PAPER_CASE_1, TARGET};
use std::path::{Path, PathBuf};

/// Arguments of `demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Folder for the plots (created if missing).
    #[arg(long, default_value = "eigenfit-demo", value_name = "DIR")]
    pub out: PathBuf,
    /// Points per axis of the grid of initial guesses of the convergence map (1e1–1e9 N/m).
    #[arg(long, default_value_t = 15, value_name = "N")]
    pub grid: usize,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
}

/// Runs `demo`.
pub fn run(args: &DemoArgs) -> Result<(), CliError> {
    if args.grid < 2 {
        return Err(input(format!("--grid {}: must be at least 2", args.grid)));
    }
    // The plots are the demo's output: their folder is checked before the work.
    crate::output::check_writable_dir(&args.out, "--out")?;
    let started = std::time::Instant::now();
    let rotor = presets::paper_rotor();
    let out = &args.out;
    let mut found = demo::run(args.grid, &mut Bars::new(args.report.quiet))?;
    let names: Vec<String> = rotor.parameters().iter().map(|p| p.name.clone()).collect();
    let mut plots: Vec<PathBuf> = simulate::write_plots(
        out,
        LABEL,
        &rotor,
        &eigenfit_core::eigen::DenseSolver,
        &TARGET,
        simulate::MapOptions { range: (1e2, 1e9), plain: true, quiet: args.report.quiet, modes: 4 },
    )?;
    let figure = Convergence {
        title: format!("{LABEL}: Table 3 case 1, every strategy from 1e2 N/m"),
        parameter_names: names.clone(),
        unit: "N/m".to_string(),
        runs: found.estimates.iter().map(Run::from_estimate).collect(),
        target: Some(TARGET.to_vec()),
        tolerance: Some((0.01, "newton/p-step tolerance, 0.01 Hz".to_string())),
        sigma_hz: None,
    };
    plots.extend(plot::write(&figure, out, "convergence")?);
    plots.extend(compare::write_maps(
        out,
        LABEL,
        rotor.parameters(),
        &found.grid,
        &found.targets,
        &found.strategies,
    )?);
    plots.extend(plot::write(&DiscoveryPlot::from_report(LABEL, &found.discovery), out, "discovery")?);
    found.report.out = out.display().to_string();
    found.report.plots = plot::names(&plots);
    found.report.seconds = started.elapsed().as_secs_f64();
    crate::output::report(args.report.json, &found.report, |r| {
        for line in text(&found, rotor.dofs(), args.grid) {
            println!("{line}");
        }
        println!("\nPlots ({} files, SVG and PNG) written to {}:", plots.len(), display_dir(out));
        for stem in stems(&plots) {
            println!("   {stem}.svg / .png");
        }
        println!("(done in {:.1} s)", r.seconds);
    });
    Ok(())
}

/// The text report, line by line.
fn text(found: &Demo, dofs: usize, grid: usize) -> Vec<String> {
    let r: &DemoReport = &found.report;
    let mut say = vec![
        format!("eigenfit demo: the paper rotor ({dofs} DOF) end to end\n"),
        "1. Table 1: natural frequencies against the support stiffnesses".to_string(),
        format!(
            "{:>10}{:>10}{:>6}{:>13}{:>13}{:>12}",
            "K1 [N/m]", "K2 [N/m]", "mode", "paper [Hz]", "model [Hz]", "diff [%]"
        ),
    ];
    for row in &r.table_1 {
        say.push(format!(
            "{:>10.0e}{:>10.0e}{:>6}{:>13.3}{:>13.3}{:>+12.2}",
            row.k[0], row.k[1], row.mode, row.paper_hz, row.model_hz, row.difference_percent
        ));
    }
    say.push(format!(
        "   largest difference {:.2} % (the paper's Fig. 2 is lost; see docs/paper-rotor.md)\n",
        found.worst_percent
    ));
    let t = &r.table_3_case_1;
    say.push(format!(
        "2. Table 3 case 1: target K1 = K2 = 1e5 N/m from 1e2 N/m; reference {:.3}, {:.3} Hz (model, 3 decimals)",
        t.reference_hz[0], t.reference_hz[1]
    ));
    say.push(format!(
        "{:<10}{:>16}{:>16}{:>8}  {}",
        "strategy", "K1 [N/m]", "K2 [N/m]", "it.", "termination"
    ));
    say.push(format!(
        "{:<10}{:>16.4e}{:>16.4e}{:>8}  {}",
        "paper", PAPER_CASE_1.0[0], PAPER_CASE_1.0[1], PAPER_CASE_1.1, "converged (paper's Table 3)"
    ));
    for e in &t.estimates {
        say.push(format!(
            "{:<10}{:>16.4e}{:>16.4e}{:>8}  {}",
            e.strategy, e.parameters[0], e.parameters[1], e.outcome.iterations, e.outcome.termination
        ));
    }
    say.push(String::new());
    say.push(format!("3. From a {grid}×{grid} grid of initial guesses (1e1–1e9 N/m), same data:"));
    for b in &r.convergence_map.strategies {
        say.push(format!(
            "   {:<8} converged from {:>3}/{} starts, {:>3} of them to the target (within {:.0} %)",
            b.strategy,
            b.converged,
            b.runs,
            b.at_target,
            AT_TARGET * 100.0
        ));
    }
    say.push(
        "   (runs that converged elsewhere found the second exact solution two frequencies allow for".into(),
    );
    say.push("   two stiffnesses: see compare-convergence.png; a third measured mode removes it)".into());
    say.push(String::new());
    let d = &found.discovery;
    say.push(
        "4. Discovery on the built-in dataset (8 modes, 0.05 % noise, a disk inertia the model lacks):"
            .into(),
    );
    say.push(format!(
        "   stiffnesses alone: K1 = {:.3e}, K2 = {:.3e} N/m (truth 2e5, 5e4), χ² = {:.0} on {} d.o.f.",
        d.base_parameters[0], d.base_parameters[1], d.before.chi2, d.before.dof
    ));
    match &r.discovery {
        Some(s) => {
            let value = s.fit.value.map_or("on".to_string(), |v| format!("{v:.4e} {}", s.fit.unit));
            say.push(format!(
                "   missing effect: {} = {value} (hidden: disk-rotary-inertia@0 = 1e-3 kg·m²)",
                s.fit.label
            ));
            say.push(format!(
                "   χ² {:.0} → {:.2}, RMS residual {:.3} → {:.4} Hz",
                s.chi2_before, s.chi2_after, s.rms.rms_residual_before_hz, s.rms.rms_residual_after_hz
            ));
        }
        None => say.push("   no single effect explains the disagreement".into()),
    }
    say
}

/// The folder as the user should look for it.
fn display_dir(dir: &Path) -> String {
    std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf()).display().to_string()
}

/// The distinct file stems, in order.
fn stems(paths: &[PathBuf]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for p in paths {
        let s = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        if !out.contains(&s) {
            out.push(s);
        }
    }
    out
}
