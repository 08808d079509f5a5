//! The `bench` report: each problem with its truth, each strategy's success rate and cost, the
//! performance profile and the ECDF of evaluations.

use super::{Cell, Report, Table};
use crate::output::significant;
use crate::plot::bench::{BenchFigure, Kind};
use eigenfit_workflow::bench::BenchReport;

/// Fills `html` with a benchmark.
pub fn fill(html: &mut Report, r: &BenchReport) {
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    html.title = format!(
        "Benchmark: {} × {} × {}",
        plural(r.problems.len(), "problem"),
        plural(r.strategies.len(), "strategy").replace("strategys", "strategies"),
        plural(r.starts, "start")
    );
    let failed: Vec<String> = r
        .summary
        .iter()
        .filter(|s| s.success_rate == 0.0)
        .map(|s| format!("{} on {}", s.strategy, s.problem))
        .collect();
    if failed.is_empty() {
        html.verdict(
            true,
            "every strategy succeeded",
            "Every strategy reached the truth of every problem from at least one start; the table says how \
             often and at what cost.",
        );
    } else {
        html.verdict(
            false,
            "some strategies never succeeded",
            format!(
                "These never reached the truth from any start: {}. The table says how often the others did.",
                failed.join(", ")
            ),
        );
    }
    let s = html.section("Summary");
    let mut t = Table::new(
        "summary",
        "Success rate and model evaluations per problem and strategy",
        &[
            "problem",
            "strategy",
            "runs",
            "success [%]",
            "median evaluations",
            "median evaluations (successes)",
            "verdicts",
        ],
    );
    for x in &r.summary {
        let verdicts: Vec<String> = x.verdicts.iter().map(|(v, n)| format!("{v} {n}")).collect();
        t.row(vec![
            Cell::text(x.problem.clone()),
            Cell::text(x.strategy.clone()),
            Cell::integer(x.runs),
            Cell::number(100.0 * x.success_rate, 3),
            Cell::plain(x.median_evaluations, 1),
            x.median_evaluations_success.map_or(Cell::text("— (none)"), |m| Cell::plain(m, 1)),
            Cell::text(verdicts.join(", ")),
        ]);
    }
    s.table(t);
    s.text(format!("{} runs in all, starts drawn with seed {}.", r.records.len(), r.seed));

    let s = html.section("Problems");
    let mut t = Table::new(
        "problems",
        "The problems: the truth each run must reach, within the relative tolerance",
        &["problem", "truth", "measured [Hz]", "tolerance (relative) [–]"],
    );
    for p in &r.problems {
        let truth: Vec<String> = p.truth.iter().map(|(n, v)| format!("{n} = {}", significant(*v))).collect();
        let measured: Vec<String> = p.measured_hz.iter().map(|f| significant(*f)).collect();
        t.row(vec![
            Cell::text(p.name.clone()),
            Cell::text(truth.join(", ")),
            Cell::text(measured.join(", ")),
            Cell::number(p.tolerance, 3),
        ]);
    }
    s.table(t);

    let s = html.section("Plots");
    s.figure(
        "Performance profile: the fraction of problems each strategy solved within τ times the fewest \
         evaluations any strategy needed.",
        &BenchFigure::new(r, Kind::Profile),
    );
    s.figure(
        "ECDF: the fraction of runs solved within a number of model evaluations.",
        &BenchFigure::new(r, Kind::Ecdf),
    );
}
