//! `eigenfit compare`: strategies × targets × a grid of initial guesses on reference data.

use crate::error::{input, CliError};
use crate::source::{parse_list, ModelArgs};
use clap::Args;
use eigenfit_core::compare::{log_space, run_grid, tensor_grid, CompareRun, CompareSettings};
use eigenfit_core::{Identifiability, StrategyKind, StructuralModel};
use serde_json::{json, Value};

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
    /// Print one JSON object (`runs` array and `summary`) instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Runs `compare`.
pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    let (rotor, label) = args.model.load()?;
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
                    "--strategies: unknown strategy `{}`; available: newton, p-step, damped",
                    s.trim()
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
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
    let runs = run_grid(&rotor, &solver.as_ref(), &targets, &initials, &strategies, &settings, |_| {})
        .map_err(|e| input(format!("reference data: {e}")))?;
    let summary = summarise(&runs, &targets, &strategies);
    if args.json {
        let runs_json: Vec<Value> = runs.iter().map(run_json).collect();
        println!(
            "{}",
            json!({"model": label, "solver": solver.name(), "decimals": args.decimals, "std_hz": args.std_hz,
                   "runs": runs_json, "summary": summary})
        );
    } else {
        println!(
            "{label}: {} runs ({} targets × {} initial guesses × {} strategies)",
            runs.len(),
            targets.len(),
            initials.len(),
            strategies.len()
        );
        println!(
            "{:<22}{:<10}{:>12}{:>14}{:>14}{:>16}",
            "target [N/m]", "strategy", "converged", "median iter", "max iter", "max rel error"
        );
        for s in &summary {
            println!(
                "{:<22}{:<10}{:>12}{:>14}{:>14}{:>16.2e}",
                s["target"]
                    .as_array()
                    .map(|t| t
                        .iter()
                        .map(|v| format!("{:.0e}", v.as_f64().unwrap_or(f64::NAN)))
                        .collect::<Vec<_>>()
                        .join(":"))
                    .unwrap_or_default(),
                s["strategy"].as_str().unwrap_or_default(),
                format!("{}/{}", s["converged"], s["runs"]),
                s["median_iterations"].to_string(),
                s["max_iterations"].to_string(),
                s["max_relative_error"].as_f64().unwrap_or(f64::NAN),
            );
        }
    }
    Ok(())
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

fn run_json(r: &CompareRun) -> Value {
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
        "seconds": r.seconds,
    });
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

fn summarise(runs: &[CompareRun], targets: &[Vec<f64>], strategies: &[StrategyKind]) -> Vec<Value> {
    let mut out = Vec::new();
    for t in targets {
        for &s in strategies {
            let group: Vec<&CompareRun> = runs.iter().filter(|r| &r.target == t && r.strategy == s).collect();
            let conv: Vec<&&CompareRun> = group.iter().filter(|r| r.converged).collect();
            let mut iters: Vec<usize> = conv.iter().map(|r| r.iterations).collect();
            iters.sort_unstable();
            let median = (!iters.is_empty()).then(|| iters[iters.len() / 2]);
            out.push(json!({
                "target": t,
                "strategy": s.name(),
                "runs": group.len(),
                "converged": conv.len(),
                "median_iterations": median,
                "max_iterations": iters.last(),
                "max_relative_error": conv.iter().map(|r| r.relative_error).fold(0.0, f64::max),
            }));
        }
    }
    out
}
