//! `eigenfit bench`: strategies × problems × starts, one record per run and a summary.

use crate::error::{CliError, EXIT_NOT_CONVERGED, EXIT_OK};
use clap::Args;
use eigenfit_workflow::bench::{self, BenchReport, BenchRequest};
use std::path::PathBuf;

/// Arguments of `bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Problems, comma-separated: built-ins (paper-table2, paper-table3, paper-table4,
    /// paper-table5, shear-frame, five-group-truss, ross-runup; `--list`) or problem files
    /// (TOML: model, measured, truth; a ROSS rotor with a run-up CSV too; docs/strategies.md).
    #[arg(long, value_name = "NAMES", value_delimiter = ',', required_unless_present = "list")]
    pub problems: Vec<String>,
    /// List the built-in problems and the registered strategies, then exit.
    #[arg(long)]
    pub list: bool,
    /// Strategies, comma-separated, by registered name with settings after colons: newton,
    /// p-step, damped, trf, gn-line-search, tikhonov, tmcmc (500 samples unless `tmcmc:samples=N`).
    #[arg(long, value_name = "NAMES", value_delimiter = ',', default_value = "newton,p-step,damped,trf")]
    pub strategies: Vec<String>,
    /// Starts per problem and strategy (the same starts for every strategy).
    #[arg(long, value_name = "N", default_value_t = 10)]
    pub starts: usize,
    /// Seed of the starts (a sampler's seed is seed + start).
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Most model evaluations of one run (default 5000 for a local strategy, a sampler's own
    /// bound for a sampler).
    #[arg(long, value_name = "N")]
    pub budget: Option<usize>,
    /// Iteration limit of a local run.
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub max_iterations: usize,
    /// Also write every record as a JSON line to this file.
    #[arg(long, value_name = "FILE")]
    pub records: Option<PathBuf>,
    /// Write performance profiles and ECDFs of evaluations (bench_profile.svg/.png,
    /// bench_ecdf.svg/.png) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// `--quiet`, `--json`.
    #[command(flatten)]
    pub report: crate::output::ReportArgs,
    /// `--report FILE.html`.
    #[command(flatten)]
    pub html: crate::report::HtmlArgs,
}

/// Runs `bench`: exit 0 when every problem and strategy reached the truth at least once, else 3
/// (the records and summary are printed either way).
pub fn run(args: &BenchArgs) -> Result<u8, CliError> {
    if args.list {
        let listing = bench::list()?;
        crate::output::report(args.report.json, &listing, print_listing);
        return Ok(EXIT_OK);
    }
    let request = BenchRequest {
        problems: args.problems.iter().map(|s| s.trim().to_string()).collect(),
        strategies: args.strategies.iter().map(|s| s.trim().to_string()).collect(),
        starts: args.starts,
        seed: args.seed,
        budget: args.budget,
        max_iterations: args.max_iterations,
    };
    // Every output is checked writable before the runs: a bench never runs for nothing.
    if let Some(path) = &args.records {
        crate::output::check_writable(path, "--records")?;
    }
    if let Some(dir) = &args.plot {
        crate::output::check_writable_dir(dir, "--plot")?;
    }
    args.html.check()?;
    let html = args.html.html.as_ref().map(|_| {
        let mut html = crate::report::Report::new("bench", "bench");
        // Problem files (built-in problems are fixed by the version).
        for p in &request.problems {
            let path = std::path::Path::new(p);
            if path.is_file() {
                html.input("problem file", path);
            } else {
                html.builtin("problem", p);
            }
        }
        html
    });
    let report = bench::run(&request)?;
    let code = if report.every_pair_succeeded() { EXIT_OK } else { EXIT_NOT_CONVERGED };
    // A write failing after the runs (a disk filled meanwhile) says what was lost and keeps the
    // bench's own exit code: the summary below stands.
    let records_written = match &args.records {
        Some(path) => {
            let mut lines = String::new();
            for r in &report.records {
                lines.push_str(&serde_json::to_string(r).map_err(|e| CliError::Failure(e.to_string()))?);
                lines.push('\n');
            }
            match crate::output::write_atomically(path, lines.as_bytes()) {
                Ok(()) => true,
                Err(e) => {
                    crate::output::report_lost("the records file", &e);
                    false
                }
            }
        }
        None => false,
    };
    let plots = match &args.plot {
        Some(dir) => crate::plot::bench::write_all(&report, dir).unwrap_or_else(|e| {
            crate::output::report_lost("plot output", &e);
            Vec::new()
        }),
        None => Vec::new(),
    };
    crate::error::set_exit_on_closed_pipe(code);
    crate::output::report(args.report.json, &report, |r| {
        print_summary(r);
        plots.iter().for_each(|w| println!("wrote {}", w.display()));
        if let (Some(path), true) = (&args.records, records_written) {
            println!("wrote {}", path.display());
        }
    });
    if let (Some(path), Some(mut html)) = (&args.html.html, html) {
        crate::report::bench::fill(&mut html, &report);
        html.write_after(path, args.report.json);
    }
    Ok(code)
}

fn print_summary(r: &BenchReport) {
    println!(
        "{} runs: {} problems × {} strategies × {} starts (seed {})",
        r.records.len(),
        r.problems.len(),
        r.strategies.len(),
        r.starts,
        r.seed
    );
    println!(
        "{:<20}{:<28}{:>8}{:>10}{:>14}{:>14}   verdicts",
        "problem", "strategy", "runs", "success", "median evals", "(successes)"
    );
    for s in &r.summary {
        let verdicts: Vec<String> = s.verdicts.iter().map(|(v, n)| format!("{v} {n}")).collect();
        println!(
            "{:<20}{:<28}{:>8}{:>9.0}%{:>14}{:>14}   {}",
            s.problem,
            s.strategy,
            s.runs,
            100.0 * s.success_rate,
            s.median_evaluations,
            s.median_evaluations_success.map_or("—".to_string(), |m| m.to_string()),
            verdicts.join(", ")
        );
    }
}

fn print_listing(l: &bench::BenchListing) {
    println!("built-in problems:");
    for p in &l.problems {
        let names: Vec<&str> = p.truth.iter().map(|(n, _)| n.as_str()).collect();
        println!(
            "  {:<18}{} parameters ({}), {} measured modes",
            p.name,
            names.len(),
            names.join(", "),
            p.measured_hz.len()
        );
    }
    println!("strategies:");
    for s in &l.strategies {
        let settings = if s.settings.is_empty() {
            String::new()
        } else {
            format!(" [settings: {}]", s.settings.join(", "))
        };
        println!("  {:<18}{}{settings}", s.name, s.summary);
    }
}
