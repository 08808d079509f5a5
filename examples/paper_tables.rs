//! Reproduces the paper's Tables 2–5 with the three strategies and prints them as Markdown
//! (the source of the tables in `docs/strategies.md`).
//!
//! Run: `cargo run --release --example paper_tables`

use eigenfit::core::analysis::{
    compare::reference_measurement, compare::run_case, compare::CompareRun, compare::CompareSettings,
    compare::ReferenceSettings, compare::SharedData, compare::DEFAULT_STRATEGIES,
};
use eigenfit::core::eigen::DenseSolver;
use eigenfit::core::problem::Problem;
use eigenfit::core::update::registry;
use eigenfit::rotor::presets;

/// One case of a paper table: the initial guess and what the paper reports.
struct Case {
    initial: f64,
    paper: Option<([f64; 2], usize)>,
}

const fn ok(k1: f64, k2: f64, loops: usize, initial: f64) -> Case {
    Case { initial, paper: Some(([k1, k2], loops)) }
}

const fn fail(initial: f64) -> Case {
    Case { initial, paper: None }
}

fn main() {
    let tables: [(&str, [f64; 2], Vec<Case>); 4] = [
        (
            "Table 2 — flexible supports (1e2 N/m)",
            [1e2, 1e2],
            vec![
                ok(9.9980e1, 1.0004e2, 3, 1e3),
                ok(9.9979e1, 1.0004e2, 6, 1e4),
                ok(9.9979e1, 1.0004e2, 8, 1e5),
                ok(9.9979e1, 1.0004e2, 497, 1e6),
                ok(9.9981e1, 1.0004e2, 17, 1e7),
                ok(1.0739e2, 1.0004e2, 20, 1e8),
            ],
        ),
        (
            "Table 3 — intermediate supports (1e5 N/m)",
            [1e5, 1e5],
            vec![
                ok(1.0000e5, 9.9993e4, 5, 1e2),
                ok(1.0000e5, 9.9993e4, 5, 1e3),
                ok(1.0000e5, 9.9993e4, 5, 1e4),
                ok(1.0000e5, 9.9993e4, 42, 1e6),
                ok(1.0000e5, 9.9993e4, 277, 5e6),
                fail(5e6),
                fail(1e7),
                fail(1e8),
            ],
        ),
        (
            "Table 4 — rigid supports (1e8 N/m)",
            [1e8, 1e8],
            vec![
                fail(1e4),
                fail(1e5),
                ok(1.0508e8, 9.7068e7, 13, 1.5e5),
                ok(1.0508e8, 9.7068e7, 13, 2e5),
                ok(1.0508e8, 9.7068e7, 11, 1e6),
                ok(1.0508e8, 9.7068e7, 8, 1e7),
            ],
        ),
        (
            "Table 5 — different supports (1e5 and 1e3 N/m)",
            [1e5, 1e3],
            vec![
                ok(1.0000e5, 9.9996e2, 5, 1e2),
                ok(1.0000e5, 9.9996e2, 5, 1e3),
                ok(1.0000e5, 9.9996e2, 5, 1e4),
                ok(1.0000e5, 9.9996e2, 6, 1e5),
                ok(1.0000e5, 9.9996e2, 82, 1e6),
            ],
        ),
    ];
    let rotor = presets::paper_rotor();
    for (title, target, cases) in &tables {
        println!("### {title}\n");
        for decimals in [Some(3), None] {
            let settings = CompareSettings {
                reference: ReferenceSettings { modes: 2, decimals, std_hz: None },
                max_iterations: 1000,
                budget: eigenfit::core::update::DEFAULT_EVALUATIONS,
            };
            let measured =
                reference_measurement(&rotor, &DenseSolver, target, &settings).expect("reference data");
            let freqs: Vec<String> = measured.modes().iter().map(|m| format!("{}", m.frequency_hz)).collect();
            println!(
                "Reference frequencies {} Hz ({}).\n",
                freqs.join(", "),
                if decimals.is_some() { "rounded to 3 decimals, as in Table 1" } else { "exact" }
            );
            println!("| case | initial [N/m] | paper | newton | p-step | damped |");
            println!("|---|---|---|---|---|---|");
            let problem = Problem::new(&rotor, DenseSolver, measured);
            let registry = registry::registry();
            let strategies: Vec<String> = DEFAULT_STRATEGIES.map(String::from).to_vec();
            let shared = SharedData::for_runs(&problem, &registry, &strategies).expect("built-in strategies");
            for (i, case) in cases.iter().enumerate() {
                let paper = match case.paper {
                    Some((k, loops)) => format!("{:.4e} / {:.4e} ({loops} it.)", k[0], k[1]),
                    None => "no convergence".to_string(),
                };
                let cells: Vec<String> = strategies
                    .iter()
                    .map(|s| {
                        cell(&run_case(
                            &problem,
                            &shared,
                            &registry,
                            target,
                            &[case.initial; 2],
                            s,
                            &settings,
                        ))
                    })
                    .collect();
                println!("| {} | {:.1e} | {paper} | {} |", i + 1, case.initial, cells.join(" | "));
            }
            println!();
        }
    }
}

fn cell(run: &CompareRun) -> String {
    if !run.outcome.converged {
        return format!("{} after {} it.", run.outcome.termination.reason, run.outcome.iterations);
    }
    let alt = if run.alternatives.is_empty() { "" } else { ", ambiguous" };
    format!("{:.4e} / {:.4e} ({} it.{alt})", run.estimate[0], run.estimate[1], run.outcome.iterations)
}
