//! `eigenfit compare`: strategies × targets × a grid of initial guesses on reference data.

use crate::error::{CliError, EXIT_NOT_CONVERGED, EXIT_OK};
use crate::output::Stream;
use crate::plot::compare_map::{CompareMaps, MapKind};
use crate::source::ModelArgs;
use crate::{plot, progress};
use clap::Args;
use eigenfit_core::analysis::compare::CompareRun;
use eigenfit_core::model::{bracketed, ParameterSet, StructuralModel};
use eigenfit_workflow::compare::{self, CompareRequest, WITHIN_1E6};
use eigenfit_workflow::estimate::axis_unit;
use std::path::{Path, PathBuf};

/// Arguments of `compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Target parameter sets, `K1:K2` separated by commas (in the parameters' units: N/m for
    /// support stiffnesses); reference data are the model's frequencies there.
    #[arg(long, value_name = "K1:K2,…")]
    pub targets: String,
    /// Log grid of initial guesses with this many points per parameter.
    #[arg(long, value_name = "N", conflicts_with = "initials")]
    pub grid: Option<usize>,
    /// Range of the grid in the parameters' units: one FROM:TO for every parameter, or one per
    /// parameter, comma-separated (`1e4:1e6,0.1:10` for a stiffness and a mass).
    #[arg(long, default_value = "1e1:1e9", value_name = "FROM:TO[,…]")]
    pub range: String,
    /// Explicit initial guesses `K1:K2` separated by commas, instead of a grid.
    #[arg(long, value_name = "K1:K2,…")]
    pub initials: Option<String>,
    /// Strategies, comma-separated, by their registered names (`eigenfit bench --list` lists
    /// them), settings after colons: newton, p-step, damped, trf, gn-line-search, tikhonov,
    /// tikhonov:choice=lcurve, damped:max_trials=50, or a strategy a library user registered.
    #[arg(long, default_value = "newton,p-step,damped")]
    pub strategies: String,
    /// Round the reference frequencies to this many decimals (the paper's Table 1: 3).
    #[arg(long)]
    pub decimals: Option<i32>,
    /// Standard deviation of each reference frequency (Hz): enables identifiability flags.
    #[arg(long)]
    pub std_hz: Option<f64>,
    /// Reference modes given to every strategy (default: as many as parameters, as in the paper);
    /// newton and p-step use the first N of them, damped uses all.
    #[arg(long)]
    pub modes: Option<usize>,
    /// Iteration limit per run.
    #[arg(long, default_value_t = 1000)]
    pub max_iterations: usize,
    /// Most model evaluations (eigen-solves) each run may spend on its fit and intervals; a run
    /// that hits it ends `budget-exhausted` (counted per target and strategy in the summary).
    #[arg(long, value_name = "N", default_value_t = eigenfit_core::update::DEFAULT_EVALUATIONS)]
    pub budget: usize,
    /// Also print a convergence map per target and strategy (grid runs with two parameters).
    #[arg(long)]
    pub maps: bool,
    /// Write the convergence and iteration maps (compare-convergence.svg/.png,
    /// compare-iterations.svg/.png) into this folder (two parameters, a grid of initial guesses).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
    /// Also append each finished run to this file as one JSON line, flushed at once, so that a
    /// long batch loses nothing already computed if it is interrupted.
    #[arg(long, value_name = "FILE.jsonl")]
    pub stream: Option<PathBuf>,
    /// Include each run's wall-clock time (`seconds`) in the JSON; off by default so that the
    /// same input gives byte-for-byte the same output.
    #[arg(long)]
    pub timing: bool,
}

/// The request these arguments make.
fn request(args: &CompareArgs) -> CompareRequest {
    CompareRequest {
        targets: args.targets.clone(),
        grid: args.grid,
        range: args.range.clone(),
        initials: args.initials.clone(),
        strategies: args.strategies.clone(),
        decimals: args.decimals,
        std_hz: args.std_hz,
        modes: args.modes,
        max_iterations: args.max_iterations,
        budget: args.budget,
        timing: args.timing,
    }
}

/// Runs `compare`; returns the exit code (3 when a run ran out of its evaluation budget: the
/// comparison is incomplete).
pub fn run(args: &CompareArgs) -> Result<u8, CliError> {
    // Every output is checked writable before the runs (the stream is opened below).
    if let Some(dir) = &args.plot {
        crate::output::check_writable_dir(dir, "--plot")?;
    }
    let (loaded, label) = args.model.load_any()?;
    // The parameters estimate fits: a rotor's `[[parameter]]` tables resolved.
    let model = loaded.updatable(&label)?;
    let solver = args.model.solver()?;
    let np = model.parameters().len();
    let plan = compare::plan(&request(args), np)?;
    let pb = progress::bar(plan.runs() as u64, "compare runs", args.report.quiet);
    // Opened after every argument is checked; the reference data are checked before the first
    // run, and the file is appended to, so a run refused there loses nothing written before.
    let mut stream = args.stream.as_deref().map(Stream::open).transpose()?;
    let report = compare::run(&label, &model, solver.as_ref(), &plan, |r| {
        pb.inc(1);
        if let Some(w) = stream.as_mut() {
            let line = serde_json::to_value(r).expect("reports serialise: every map key is a string");
            w.append(&line.to_string());
        }
    });
    pb.finish_and_clear();
    let mut report = report?;
    let plots = match &args.plot {
        // A write failing after the runs says what was lost; the comparison below stands.
        Some(dir) => {
            write_maps(dir, &label, model.parameters(), &report.raw, &plan.targets, &plan.strategies)
                .unwrap_or_else(|e| {
                    crate::output::report_lost("plot output", &e);
                    Vec::new()
                })
        }
        None => Vec::new(),
    };
    report.plots = args.plot.as_ref().map(|_| plot::names(&plots));
    let cut: usize = report.summary.iter().map(|s| s.budget_exhausted).sum();
    let code = if cut > 0 { EXIT_NOT_CONVERGED } else { EXIT_OK };
    crate::error::set_exit_on_closed_pipe(code);
    let target_heading = format!("target{}", bracketed(&axis_unit(model.parameters())));
    crate::output::report(args.report.json, &report, |report| {
        println!(
            "{label}: {} runs ({} targets × {} initial guesses × {} strategies), {} reference modes",
            report.runs.len(),
            plan.targets.len(),
            plan.initials.len(),
            plan.strategies.len(),
            report.reference.modes
        );
        let width = report.summary.iter().map(|s| s.strategy.chars().count() + 1).fold(9, usize::max);
        let tw = report
            .summary
            .iter()
            .map(|s| s.target.iter().map(|v| format!("{v:.0e}").len() + 1).sum::<usize>())
            .chain([target_heading.chars().count() + 1, 16])
            .max()
            .unwrap_or(16);
        println!(
            "{:<tw$}{:<width$}{:>11}{:>12}{:>9}{:>9}{:>15}{:>11}",
            target_heading,
            "strategy",
            "converged",
            "err ≤ 1e-6",
            "it. med",
            "it. max",
            "max rel err",
            "ambiguous"
        );
        for s in &report.summary {
            let target: Vec<String> = s.target.iter().map(|v| format!("{v:.0e}")).collect();
            let fmt = |v: Option<usize>| v.map_or("-".to_string(), |v| v.to_string());
            println!(
                "{:<tw$}{:<width$}{:>11}{:>12}{:>9}{:>9}{:>15}{:>11}",
                target.join(":"),
                s.strategy,
                format!("{}/{}", s.converged, s.runs),
                s.converged_within_1e6,
                fmt(s.median_iterations),
                fmt(s.max_iterations),
                s.max_relative_error.map_or("-".to_string(), |e| format!("{e:.2e}")),
                s.ambiguous
            );
        }
        println!("(it. med/max: median and largest iterations of the converged runs; max rel err: largest |estimate/target − 1| [–]; ambiguous: converged runs for which another solution fits the data at least as well, by the χ² test of the verdicts)");
        if cut > 0 {
            println!(
                "{cut} run(s) ran out of their evaluation budget ({} model evaluations each): their results are incomplete; raise it with --budget",
                args.budget
            );
        }
        if args.maps && np == 2 {
            print_maps(&report.raw, &plan.targets, &plan.strategies);
        }
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    });
    // A write failure after the results are printed says what was lost; the code stays the
    // comparison's own.
    if let Some(lost) = stream.and_then(|w| w.finish(report.runs.len())) {
        eprintln!("eigenfit: {lost}");
    }
    Ok(code)
}

/// Writes the convergence and iteration maps; a note on stderr (and nothing written) unless the
/// model has two parameters and the initial guesses form a grid.
pub fn write_maps(
    dir: &Path,
    label: &str,
    params: &ParameterSet,
    runs: &[CompareRun],
    targets: &[Vec<f64>],
    strategies: &[String],
) -> Result<Vec<PathBuf>, CliError> {
    if params.len() != 2 {
        eprintln!("eigenfit: --plot: compare maps need a model with two parameters; none written");
        return Ok(Vec::new());
    }
    let (x, y) =
        (params.iter().next().expect("two parameters"), params.iter().nth(1).expect("two parameters"));
    let names = [x.name.clone(), y.name.clone()];
    let units = [x.unit().to_string(), y.unit().to_string()];
    let mut written = Vec::new();
    for (kind, stem) in
        [(MapKind::Convergence, "compare-convergence"), (MapKind::Iterations, "compare-iterations")]
    {
        match CompareMaps::from_runs(label, names.clone(), units.clone(), runs, targets, strategies, kind) {
            Some(maps) => written.extend(plot::write(&maps, dir, stem)?),
            None => {
                eprintln!(
                    "eigenfit: --plot: compare maps need a grid of initial guesses (--grid N); none written"
                );
                return Ok(written);
            }
        }
    }
    Ok(written)
}

/// Convergence maps: one character per initial guess, K1 down the rows, K2 across.
fn print_maps(runs: &[CompareRun], targets: &[Vec<f64>], strategies: &[String]) {
    let mut k1: Vec<f64> = runs.iter().map(|r| r.initial[0]).collect();
    k1.sort_by(f64::total_cmp);
    k1.dedup();
    println!(
        "\nmaps: ● converged to the target (rel. error ≤ 1e-6), ○ converged elsewhere, · no convergence"
    );
    for t in targets {
        for s in strategies {
            let target: Vec<String> = t.iter().map(|v| format!("{v:.0e}")).collect();
            println!(
                "\n{} from K1 (rows, {:.0e} → {:.0e}) × K2 (columns), target {}",
                s,
                k1[0],
                k1[k1.len() - 1],
                target.join(":")
            );
            for &a in &k1 {
                let row: String = runs
                    .iter()
                    .filter(|r| &r.target == t && &r.strategy == s && r.initial[0] == a)
                    .map(|r| match (r.outcome.converged, r.relative_error <= WITHIN_1E6) {
                        (true, true) => '●',
                        (true, false) => '○',
                        _ => '·',
                    })
                    .collect();
                println!("  {a:>8.1e}  {row}");
            }
        }
    }
}
