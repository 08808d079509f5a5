//! The independent-data discovery study of docs/discovery.md: every draw of
//! `tests/fixtures/discovery/independent.toml` (numpy-generated, see `generate.py` there),
//! scored per case and noise level, with the eigen-solves spent and the slowest run's wall time.
//!
//! cargo run --release -p eigenfit-rotor --example discovery_study
//! (`STUDY_CASES=pedestal,clean` for some cases only, `STUDY_VERBOSE=1` for every answer,
//! `STUDY_BUDGET=N` for another evaluation budget than the default,
//! `STUDY_SET=heldout` for the draws of `generate.py --heldout`, `STUDY_SET=fresh` for those of
//! `generate.py --fresh`, `STUDY_SET=fresh2` for those of `generate.py --fresh2`,
//! `STUDY_SET=fresh3` for those of `generate.py --fresh3`, `STUDY_SET=fresh4` for those of
//! `generate.py --fresh4`, instead of the design draws)

#[path = "../tests/common/study.rs"]
mod study;

use std::sync::atomic::Ordering;
use std::time::Instant;
use study::Outcome;

fn main() {
    let set = std::env::var("STUDY_SET").unwrap_or_default();
    let (fixtures, name) = match set.as_str() {
        "heldout" => (study::load_heldout(), "held-out (heldout.toml, seed 99173)"),
        "fresh" => (study::load_fresh(), "fresh held-out (fresh.toml, seed 60411)"),
        "fresh2" => (study::load_fresh2(), "second fresh held-out (fresh2.toml, seed 53913)"),
        "fresh3" => (study::load_fresh3(), "third fresh held-out (fresh3.toml, seed 67138)"),
        "fresh4" => (study::load_fresh4(), "fourth fresh held-out (fresh4.toml, seed 74813)"),
        _ => (study::load(), "design (independent.toml, seed 20261123)"),
    };
    println!("draws: {name}\n");
    println!(
        "| case | noise | named | ambiguous (honest) | nothing | wrong | truth in 95 % interval | eigen-solves (mean, most) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut slowest = 0.0f64;
    // The most CPU time of one run: on a shared machine the wall time measures the neighbours too.
    let (mut most_cpu, mut total_cpu, mut runs) = (0.0f64, 0.0f64, 0usize);
    // STUDY_BUDGET=N gives each run N evaluations instead of the default.
    let mut options = eigenfit_core::discovery::DiscoveryOptions::default();
    if let Some(n) = std::env::var("STUDY_BUDGET").ok().and_then(|n| n.parse().ok()) {
        options.max_evaluations = n;
    }
    // STUDY_CASES=pedestal,clean runs only those cases.
    let only = std::env::var("STUDY_CASES").ok();
    let wanted = |name: &str| only.as_deref().is_none_or(|o| o.split(',').any(|c| c == name));
    for case in fixtures.case.iter().filter(|c| wanted(&c.name)) {
        let mut noises: Vec<f64> =
            fixtures.draw.iter().filter(|d| d.case == case.name).map(|d| d.noise).collect();
        noises.dedup();
        for noise in noises {
            let mut counts = [0usize; 4];
            let (mut covered, mut total) = (0, 0);
            let (mut solves, mut most, mut exhausted) = (0, 0, 0);
            for draw in fixtures.draw.iter().filter(|d| d.case == case.name && d.noise == noise) {
                let t = Instant::now();
                let cpu = cpu_seconds();
                let solver = study::CountingSolver::default();
                let found = study::run_with(&draw.frequency_hz, &draw.std_hz, &solver, &options);
                slowest = slowest.max(t.elapsed().as_secs_f64());
                let cpu = cpu_seconds() - cpu;
                (most_cpu, total_cpu, runs) = (most_cpu.max(cpu), total_cpu + cpu, runs + 1);
                let spent = solver.solves.load(Ordering::Relaxed);
                (solves, most) = (solves + spent, most.max(spent));
                exhausted += usize::from(found.report.budget_exhausted);
                let named = found.effects;
                let (outcome, inside) = study::score(&case.expect, &named);
                counts[outcome as usize] += 1;
                if matches!(outcome, Outcome::Named) {
                    total += 1;
                    covered += usize::from(inside);
                }
                if std::env::var_os("STUDY_VERBOSE").is_some() {
                    let labels: Vec<String> = named
                        .iter()
                        .map(|n| {
                            let alts: Vec<&str> = n.ambiguous_with.iter().map(|a| a.label.as_str()).collect();
                            format!("{}={:?} (ΔAICc {:.1}) ~{:?}", n.label, n.value, n.delta_aicc, alts)
                        })
                        .collect();
                    eprintln!(
                        "{} {noise} {}: {outcome:?} {labels:?} {spent} solves {:?}",
                        case.name, draw.draw, found.report.spending
                    );
                }
            }
            let n: usize = counts.iter().sum();
            println!(
                "| {} | {:.2} % | {}/{n} | {}/{n} | {}/{n} | {}/{n} | {} | {}, {}{} |",
                case.name,
                noise * 100.0,
                counts[0],
                counts[1],
                counts[2],
                counts[3],
                if total > 0 { format!("{covered}/{total}") } else { "–".into() },
                solves / n,
                most,
                if exhausted > 0 { format!(" ({exhausted} out of budget)") } else { String::new() }
            );
        }
    }
    println!("\nslowest discovery run: {slowest:.2} s");
    println!(
        "most CPU time of one run: {most_cpu:.2} s (mean {:.3} s over {runs} runs)",
        total_cpu / runs.max(1) as f64
    );
}

/// CPU time of this thread (user + system), from /proc (Linux; 10 ms ticks), as
/// `discovery_timing` measures it.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    // Fields after the parenthesised command name (the first of them, the state, is field 3);
    // utime and stime are fields 14 and 15.
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<&str> = after.split_whitespace().collect();
    let field = |n: usize| fields.get(n - 3).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (field(14) + field(15)) / 100.0
}
