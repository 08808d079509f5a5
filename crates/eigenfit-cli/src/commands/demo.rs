//! `eigenfit demo`: the paper rotor end to end — Table 1 side by side, the estimation of Table 3
//! case 1 with all three strategies, a convergence map, and discovery of a hidden effect in a
//! built-in dataset — with a short report and every plot kind written to a folder.

use crate::commands::{compare, simulate};
use crate::error::{input, CliError};
use crate::plot::convergence::{Convergence, Run};
use crate::plot::critical_speed::PAPER_TABLE_1;
use crate::plot::discovery::DiscoveryPlot;
use crate::{measured, plot, progress};
use clap::Args;
use eigenfit_core::analysis::{
    compare::log_space, compare::reference_measurement, compare::run_grid, compare::tensor_grid,
    compare::CompareSettings,
};
use eigenfit_core::discovery::{discover, DiscoveryOptions};
use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::Problem;
use eigenfit_core::update::{Driver, StrategyKind};
use eigenfit_rotor::presets;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The built-in dataset: 8 noisy frequencies of the paper rotor at K1 = 2e5, K2 = 5e4 N/m with a
/// diametral inertia of 1e-3 kg·m² on disk 0 that the model lacks (docs/discovery.md).
const HIDDEN_EFFECT_CSV: &str = include_str!("../../../../examples/measured_hidden_effect.csv");

/// Table 3 case 1: the target and the start (N/m).
const TARGET: [f64; 2] = [1e5, 1e5];
const INITIAL: [f64; 2] = [1e2, 1e2];
/// The paper's result for Table 3 case 1: K1, K2 (N/m) and iterations.
const PAPER_CASE_1: ([f64; 2], usize) = ([1.0000e5, 9.9993e4], 5);

/// Arguments of `demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Folder for the plots (created if missing).
    #[arg(long, default_value = "eigenfit-demo", value_name = "DIR")]
    pub out: PathBuf,
    /// Points per axis of the grid of initial guesses of the convergence map (1e1–1e9 N/m).
    #[arg(long, default_value_t = 15, value_name = "N")]
    pub grid: usize,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
    /// Print one JSON object instead of the report.
    #[arg(long)]
    pub json: bool,
}

/// Runs `demo`.
pub fn run(args: &DemoArgs) -> Result<(), CliError> {
    if args.grid < 2 {
        return Err(input(format!("--grid {}: must be at least 2", args.grid)));
    }
    let started = std::time::Instant::now();
    let label = "paper-rotor";
    let rotor = presets::paper_rotor();
    let solver = DenseSolver;
    let names: Vec<String> = rotor.parameters().iter().map(|p| p.name.clone()).collect();
    let out = &args.out;
    let mut plots: Vec<PathBuf> = Vec::new();
    let mut report: Vec<String> = Vec::new();
    let mut say = |line: String| report.push(line);

    // 1. Table 1 side by side.
    say(format!("eigenfit demo: the paper rotor ({} DOF) end to end\n", rotor.dofs()));
    say("1. Table 1: natural frequencies against the support stiffnesses".to_string());
    say(format!(
        "{:>10}{:>10}{:>6}{:>13}{:>13}{:>12}",
        "K1 [N/m]", "K2 [N/m]", "mode", "paper [Hz]", "model [Hz]", "diff [%]"
    ));
    let mut table = Vec::new();
    let mut worst = 0.0_f64;
    for (k, paper) in PAPER_TABLE_1 {
        let system = rotor.assemble(&k).map_err(|e| CliError::Failure(e.to_string()))?;
        let f = solver.lowest(&system, 2).map_err(|e| CliError::Failure(e.to_string()))?.frequencies_hz();
        for m in 0..2 {
            let diff = (f[m] / paper[m] - 1.0) * 100.0;
            worst = worst.max(diff.abs());
            say(format!(
                "{:>10.0e}{:>10.0e}{:>6}{:>13.3}{:>13.3}{:>+12.2}",
                k[0],
                k[1],
                m + 1,
                paper[m],
                f[m],
                diff
            ));
            table.push(json!({"k": k, "mode": m + 1, "paper_hz": paper[m], "model_hz": f[m], "difference_percent": diff}));
        }
    }
    say(format!(
        "   largest difference {worst:.2} % (the paper's Fig. 2 is lost; see docs/paper-rotor.md)\n"
    ));
    plots.extend(simulate::write_plots(
        out,
        label,
        &rotor,
        &solver,
        &TARGET,
        simulate::MapOptions { range: (1e2, 1e9), plain: true, quiet: args.quiet },
    )?);

    // 2. Table 3 case 1 with all three strategies.
    let settings = CompareSettings { modes: 2, decimals: Some(3), std_hz: None, max_iterations: 1000 };
    let measured = reference_measurement(&rotor, &solver, &TARGET, &settings).map_err(CliError::Failure)?;
    let reference: Vec<f64> = measured.modes().iter().map(|m| m.frequency_hz).collect();
    say(format!(
        "2. Table 3 case 1: target K1 = K2 = 1e5 N/m from 1e2 N/m; reference {:.3}, {:.3} Hz (model, 3 decimals)",
        reference[0], reference[1]
    ));
    say(format!("{:<10}{:>16}{:>16}{:>8}  {}", "strategy", "K1 [N/m]", "K2 [N/m]", "it.", "termination"));
    say(format!(
        "{:<10}{:>16.4e}{:>16.4e}{:>8}  {}",
        "paper", PAPER_CASE_1.0[0], PAPER_CASE_1.0[1], PAPER_CASE_1.1, "converged (paper's Table 3)"
    ));
    let problem = Problem::new(&rotor, &solver, measured);
    let mut runs = Vec::new();
    let mut estimates = Vec::new();
    for kind in StrategyKind::ALL {
        let mut strategy = kind.build();
        let e = Driver { max_iterations: 1000 }
            .run(&problem, strategy.as_mut(), &INITIAL, &mut [])
            .map_err(|e| CliError::Failure(e.to_string()))?;
        say(format!(
            "{:<10}{:>16.4e}{:>16.4e}{:>8}  {}",
            e.strategy, e.parameters[0], e.parameters[1], e.iterations, e.termination
        ));
        estimates.push(json!({"strategy": e.strategy, "parameters": e.parameters, "iterations": e.iterations,
                              "converged": e.termination.is_converged(), "termination": e.termination.to_string()}));
        runs.push(Run::from_estimate(&e));
    }
    say(String::new());
    let figure = Convergence {
        title: format!("{label}: Table 3 case 1, every strategy from 1e2 N/m"),
        parameter_names: names.clone(),
        unit: "N/m".to_string(),
        runs,
        target: Some(TARGET.to_vec()),
        tolerance_hz: Some(0.01),
        sigma_hz: None,
    };
    plots.extend(plot::write(&figure, out, "convergence")?);

    // 3. Where each strategy converges from: a grid of initial guesses.
    let initials = tensor_grid(&log_space(1e1, 1e9, args.grid), 2);
    let targets = vec![TARGET.to_vec()];
    let strategies = StrategyKind::ALL.to_vec();
    let pb = progress::bar((initials.len() * strategies.len()) as u64, "convergence map", args.quiet);
    let grid = run_grid(&rotor, &solver, &targets, &initials, &strategies, &settings, |_| pb.inc(1));
    pb.finish_and_clear();
    let grid = grid.map_err(CliError::Failure)?;
    say(format!("3. From a {n}×{n} grid of initial guesses (1e1–1e9 N/m), same data:", n = args.grid));
    let mut basin = Vec::new();
    for &s in &strategies {
        let group: Vec<_> = grid.iter().filter(|r| r.strategy == s).collect();
        let converged = group.iter().filter(|r| r.converged).count();
        let at_target =
            group.iter().filter(|r| r.converged && r.relative_error <= plot::compare_map::AT_TARGET).count();
        say(format!(
            "   {:<8} converged from {converged:>3}/{} starts, {at_target:>3} of them to the target (within 10 %)",
            s.name(),
            group.len()
        ));
        basin.push(json!({"strategy": s.name(), "runs": group.len(), "converged": converged, "at_target": at_target}));
    }
    say("   (runs that converged elsewhere found the second exact solution two frequencies allow for".into());
    say("   two stiffnesses: see compare-convergence.png; a third measured mode removes it)".into());
    say(String::new());
    plots.extend(compare::write_maps(out, label, &names, &grid, &targets, &strategies)?);

    // 4. Discovery of a hidden effect.
    let data = measured::parse(HIDDEN_EFFECT_CSV)
        .map_err(|e| CliError::Failure(format!("built-in dataset: line {e}")))?;
    let pb = progress::spinner("discovering the hidden effect", args.quiet);
    let options = DiscoveryOptions::default();
    let found = discover(&rotor, &solver, &data, &rotor.candidates(), &rotor.nominal_stiffnesses(), &options);
    pb.finish_and_clear();
    let found = found.map_err(|e| CliError::Failure(e.to_string()))?;
    say("4. Discovery on the built-in dataset (8 modes, 0.05 % noise, a disk inertia the model lacks):"
        .into());
    say(format!(
        "   stiffnesses alone: K1 = {:.3e}, K2 = {:.3e} N/m (truth 2e5, 5e4), χ² = {:.0} on {} d.o.f.",
        found.base_parameters[0], found.base_parameters[1], found.chi2_before, found.dof_before
    ));
    let discovery_json = match &found.selected {
        Some(s) => {
            let value = s.value.map_or("on".to_string(), |v| format!("{v:.4e} {}", s.unit));
            say(format!(
                "   missing effect: {} = {value} (hidden: disk-rotary-inertia@0 = 1e-3 kg·m²)",
                s.label
            ));
            say(format!(
                "   χ² {:.0} → {:.2}, RMS residual {:.3} → {:.4} Hz",
                found.chi2_before, s.chi2, found.rms_before_hz, found.rms_after_hz
            ));
            json!({"kind": s.kind, "location": s.location, "value": s.value, "unit": s.unit,
                   "chi2_before": found.chi2_before, "chi2_after": s.chi2,
                   "rms_residual_before_hz": found.rms_before_hz, "rms_residual_after_hz": found.rms_after_hz})
        }
        None => {
            say("   no single effect explains the disagreement".into());
            Value::Null
        }
    };
    plots.extend(plot::write(&DiscoveryPlot::from_report(label, &found), out, "discovery")?);

    let seconds = started.elapsed().as_secs_f64();
    if args.json {
        crate::output::emit_json(json!({
            "model": label,
            "table_1": table,
            "table_3_case_1": {"target": TARGET, "initial": INITIAL, "reference_hz": reference,
                               "estimates": estimates},
            "convergence_map": {"grid": args.grid, "strategies": basin},
            "discovery": discovery_json,
            "out": out.display().to_string(),
            "plots": plot::names(&plots),
            "seconds": seconds,
        }));
    } else {
        for line in &report {
            println!("{line}");
        }
        println!("\nPlots ({} files, SVG and PNG) written to {}:", plots.len(), display_dir(out));
        for stem in stems(&plots) {
            println!("   {stem}.svg / .png");
        }
        println!("(done in {seconds:.1} s)");
    }
    Ok(())
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
