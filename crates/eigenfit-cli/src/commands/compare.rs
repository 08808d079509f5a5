//! `eigenfit compare`: strategies × targets × a grid of initial guesses on reference data.

use crate::error::{input, CliError};
use crate::output::Stream;
use crate::plot::compare_map::{CompareMaps, MapKind};
use crate::source::{parse_list, ModelArgs};
use crate::{plot, progress};
use clap::Args;
use eigenfit_core::analysis::Identifiability;
use eigenfit_core::analysis::{
    compare::log_space, compare::run_grid, compare::tensor_grid, compare::CompareRun,
    compare::CompareSettings,
};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::update::StrategyKind;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Arguments of `compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Target stiffness sets, `K1:K2` separated by commas (N/m); reference data are the model's
    /// frequencies there.
    #[arg(long, value_name = "K1:K2,…")]
    pub targets: String,
    /// Log grid of initial guesses with this many points per parameter.
    #[arg(long, value_name = "N", conflicts_with = "initials")]
    pub grid: Option<usize>,
    /// Range of the grid, FROM:TO in N/m.
    #[arg(long, default_value = "1e1:1e9", value_name = "FROM:TO")]
    pub range: String,
    /// Explicit initial guesses `K1:K2` separated by commas, instead of a grid.
    #[arg(long, value_name = "K1:K2,…")]
    pub initials: Option<String>,
    /// Strategies, comma-separated: newton, p-step, damped.
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
    /// Also print a convergence map per target and strategy (grid runs with two parameters).
    #[arg(long)]
    pub maps: bool,
    /// Write the convergence and iteration maps (compare-convergence.svg/.png,
    /// compare-iterations.svg/.png) into this folder (two parameters, a grid of initial guesses).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Also append each finished run to this file as one JSON line, flushed at once, so that a
    /// long batch loses nothing already computed if it is interrupted.
    #[arg(long, value_name = "FILE.jsonl")]
    pub stream: Option<PathBuf>,
    /// Include each run's wall-clock time (`seconds`) in the JSON; off by default so that the
    /// same input gives byte-for-byte the same output.
    #[arg(long)]
    pub timing: bool,
    /// Print one JSON object (`runs` array and `summary`) instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Most runs one `compare` accepts: far beyond any study (the paper's maps are 10⁴), checked
/// before anything is allocated.
pub const MAX_RUNS: usize = 1_000_000;

/// Runs `compare`.
pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    let (model, label) = args.model.load_any()?;
    let rotor = &model;
    let solver = args.model.solver()?;
    let np = rotor.parameters().len();
    let targets = points("--targets", &args.targets, np)?;
    let initials = match (&args.initials, args.grid) {
        (Some(text), _) => points("--initials", text, np)?,
        (None, Some(n)) if n >= 2 => {
            let r = parse_list("--range", &args.range.replace(':', ","))?;
            if r.len() != 2 || !(r[0] > 0.0 && r[1] > r[0]) {
                return Err(input(format!("--range `{}`: expected FROM:TO with 0 < FROM < TO", args.range)));
            }
            // Counted before the grid is built: 10000^2 points would exhaust memory first.
            u32::try_from(np)
                .ok()
                .and_then(|d| n.checked_pow(d))
                .filter(|&c| c <= MAX_RUNS)
                .ok_or_else(|| {
                    input(format!(
                        "--grid {n}: {n}^{np} initial guesses, more than the {MAX_RUNS} runs compare accepts; use a smaller --grid"
                    ))
                })?;
            tensor_grid(&log_space(r[0], r[1], n), np)
        }
        _ => return Err(input("give --grid N (N ≥ 2) or --initials K1:K2,…")),
    };
    let strategies = args
        .strategies
        .split(',')
        .map(|s| {
            StrategyKind::from_name(s.trim()).ok_or_else(|| {
                input(format!(
                    "--strategies: unknown strategy `{}`; available: newton, p-step, damped (alias levenberg-marquardt)",
                    s.trim()
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    // Beyond ±15 decimals rounding either changes nothing a double holds or overflows to NaN.
    if let Some(d) = args.decimals.filter(|d| !(-15..=15).contains(d)) {
        return Err(input(format!(
            "--decimals {d}: must be between -15 and 15 (a double holds about 16 digits)"
        )));
    }
    let total_runs = targets.len().saturating_mul(initials.len()).saturating_mul(strategies.len());
    if total_runs > MAX_RUNS {
        return Err(input(format!(
            "{} targets × {} initial guesses × {} strategies = {total_runs} runs, more than the {MAX_RUNS} compare accepts",
            targets.len(),
            initials.len(),
            strategies.len()
        )));
    }
    if let Some(s) = args.std_hz {
        if !(s.is_finite() && s > 0.0) {
            return Err(input(format!("--std-hz {s}: must be a positive finite number")));
        }
    }
    let settings = CompareSettings {
        modes: args.modes.unwrap_or(np).max(np),
        decimals: args.decimals,
        std_hz: args.std_hz,
        max_iterations: args.max_iterations,
    };
    let total = (targets.len() * initials.len() * strategies.len()) as u64;
    let pb = progress::bar(total, "compare runs", args.quiet);
    // Opened after every argument is checked; run_grid checks the reference data before its
    // first run, and the file is appended to, so a run refused there loses nothing written before.
    let mut stream = args.stream.as_deref().map(Stream::open).transpose()?;
    let runs = run_grid(&rotor, &solver.as_ref(), &targets, &initials, &strategies, &settings, |r| {
        pb.inc(1);
        if let Some(w) = stream.as_mut() {
            w.append(&run_json(r, args.timing).to_string());
        }
    });
    pb.finish_and_clear();
    let runs = runs.map_err(|e| input(format!("reference data: {e}")))?;
    let summary = summarise(&runs, &targets, &strategies);
    let names: Vec<String> = rotor.parameters().iter().map(|p| p.name.clone()).collect();
    let plots = match &args.plot {
        Some(dir) => write_maps(dir, &label, &names, &runs, &targets, &strategies)?,
        None => Vec::new(),
    };
    if args.json {
        let runs_json: Vec<Value> = runs.iter().map(|r| run_json(r, args.timing)).collect();
        let summary_json: Vec<Value> = summary.iter().map(Summary::to_json).collect();
        let mut out = json!({"model": label, "solver": solver.name(), "modes": settings.modes,
                   "decimals": args.decimals, "std_hz": args.std_hz, "runs": runs_json, "summary": summary_json});
        if args.plot.is_some() {
            out["plots"] = json!(plot::names(&plots));
        }
        crate::output::emit_json(out);
    } else {
        println!(
            "{label}: {} runs ({} targets × {} initial guesses × {} strategies), {} reference modes",
            runs.len(),
            targets.len(),
            initials.len(),
            strategies.len(),
            settings.modes
        );
        println!(
            "{:<16}{:<9}{:>11}{:>12}{:>9}{:>9}{:>15}{:>11}",
            "target [N/m]",
            "strategy",
            "converged",
            "err ≤ 1e-6",
            "it. med",
            "it. max",
            "max rel err",
            "ambiguous"
        );
        for s in &summary {
            let target: Vec<String> = s.target.iter().map(|v| format!("{v:.0e}")).collect();
            let fmt = |v: Option<usize>| v.map_or("-".to_string(), |v| v.to_string());
            println!(
                "{:<16}{:<9}{:>11}{:>12}{:>9}{:>9}{:>15.2e}{:>11}",
                target.join(":"),
                s.strategy.name(),
                format!("{}/{}", s.converged, s.runs),
                s.within_1e6,
                fmt(s.median_iterations),
                fmt(s.max_iterations),
                s.max_relative_error,
                // Only damped runs are checked for other solutions: a 0 elsewhere would mean nothing.
                if s.strategy == StrategyKind::LevenbergMarquardt {
                    s.ambiguous.to_string()
                } else {
                    "-".to_string()
                }
            );
        }
        println!("(it. med/max: median and largest iterations of the converged runs; max rel err: largest |estimate/target − 1| [–]; ambiguous: converged damped runs whose data also fit another solution, - where not checked)");
        if args.maps && np == 2 {
            print_maps(&runs, &targets, &strategies);
        }
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
    }
    // A write failure ends the command non-zero after the results are printed.
    stream.map_or(Ok(()), |w| w.finish(runs.len()))
}

/// Writes the convergence and iteration maps; a note on stderr (and nothing written) unless the
/// model has two parameters and the initial guesses form a grid.
pub fn write_maps(
    dir: &Path,
    label: &str,
    names: &[String],
    runs: &[CompareRun],
    targets: &[Vec<f64>],
    strategies: &[StrategyKind],
) -> Result<Vec<PathBuf>, CliError> {
    if names.len() != 2 {
        eprintln!("eigenfit: --plot: compare maps need a model with two parameters; none written");
        return Ok(Vec::new());
    }
    let names = [names[0].clone(), names[1].clone()];
    let mut written = Vec::new();
    for (kind, stem) in
        [(MapKind::Convergence, "compare-convergence"), (MapKind::Iterations, "compare-iterations")]
    {
        match CompareMaps::from_runs(label, names.clone(), runs, targets, strategies, kind) {
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

fn points(flag: &str, text: &str, np: usize) -> Result<Vec<Vec<f64>>, CliError> {
    text.split(',')
        .map(|item| {
            let p = parse_list(flag, &item.replace(':', ","))?;
            if p.len() != np || p.iter().any(|&v| v <= 0.0) {
                return Err(input(format!(
                    "{flag}: `{item}` must be {np} positive stiffnesses joined by `:`"
                )));
            }
            Ok(p)
        })
        .collect()
}

fn run_json(r: &CompareRun, timing: bool) -> Value {
    let mut v = json!({
        "strategy": r.strategy.name(),
        "target": r.target,
        "initial": r.initial,
        "converged": r.converged,
        "termination": r.termination,
        "iterations": r.iterations,
        "evaluations": r.evaluations,
        "estimate": r.estimate,
        "relative_error": r.relative_error,
    });
    if timing {
        v["seconds"] = json!(r.seconds);
    }
    if r.strategy == StrategyKind::LevenbergMarquardt && r.converged {
        v["alternative_solutions"] = json!(r.alternatives);
    }
    if let Some(ids) = &r.identifiability {
        v["identifiable"] = ids
            .iter()
            .map(|i| match i {
                Identifiability::Determined => json!(true),
                Identifiability::LowerBoundOnly { lower } => json!({"lower_bound": lower}),
                Identifiability::UpperBoundOnly { upper } => json!({"upper_bound": upper}),
                Identifiability::Undetermined => json!(false),
            })
            .collect();
    }
    v
}

/// Per target and strategy: how many runs converged, how fast, how accurately.
struct Summary {
    target: Vec<f64>,
    strategy: StrategyKind,
    runs: usize,
    converged: usize,
    within_1e6: usize,
    ambiguous: usize,
    median_iterations: Option<usize>,
    max_iterations: Option<usize>,
    max_relative_error: f64,
}

impl Summary {
    fn to_json(&self) -> Value {
        json!({
            "target": self.target,
            "strategy": self.strategy.name(),
            "runs": self.runs,
            "converged": self.converged,
            "converged_within_1e-6": self.within_1e6,
            "ambiguous": (self.strategy == StrategyKind::LevenbergMarquardt).then_some(self.ambiguous),
            "median_iterations": self.median_iterations,
            "max_iterations": self.max_iterations,
            "max_relative_error": self.max_relative_error,
        })
    }
}

fn summarise(runs: &[CompareRun], targets: &[Vec<f64>], strategies: &[StrategyKind]) -> Vec<Summary> {
    let mut out = Vec::new();
    for t in targets {
        for &s in strategies {
            let group: Vec<&CompareRun> = runs.iter().filter(|r| &r.target == t && r.strategy == s).collect();
            let conv: Vec<&&CompareRun> = group.iter().filter(|r| r.converged).collect();
            let mut iters: Vec<usize> = conv.iter().map(|r| r.iterations).collect();
            iters.sort_unstable();
            out.push(Summary {
                target: t.clone(),
                strategy: s,
                runs: group.len(),
                converged: conv.len(),
                within_1e6: conv.iter().filter(|r| r.relative_error <= 1e-6).count(),
                ambiguous: conv.iter().filter(|r| !r.alternatives.is_empty()).count(),
                median_iterations: (!iters.is_empty()).then(|| iters[iters.len() / 2]),
                max_iterations: iters.last().copied(),
                max_relative_error: conv.iter().map(|r| r.relative_error).fold(0.0, f64::max),
            });
        }
    }
    out
}

/// Convergence maps: one character per initial guess, K1 down the rows, K2 across.
fn print_maps(runs: &[CompareRun], targets: &[Vec<f64>], strategies: &[StrategyKind]) {
    let mut k1: Vec<f64> = runs.iter().map(|r| r.initial[0]).collect();
    k1.sort_by(f64::total_cmp);
    k1.dedup();
    println!(
        "\nmaps: ● converged to the target (rel. error ≤ 1e-6), ○ converged elsewhere, · no convergence"
    );
    for t in targets {
        for &s in strategies {
            let target: Vec<String> = t.iter().map(|v| format!("{v:.0e}")).collect();
            println!(
                "\n{} from K1 (rows, {:.0e} → {:.0e}) × K2 (columns), target {}",
                s.name(),
                k1[0],
                k1[k1.len() - 1],
                target.join(":")
            );
            for &a in &k1 {
                let row: String = runs
                    .iter()
                    .filter(|r| &r.target == t && r.strategy == s && r.initial[0] == a)
                    .map(|r| match (r.converged, r.relative_error <= 1e-6) {
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
