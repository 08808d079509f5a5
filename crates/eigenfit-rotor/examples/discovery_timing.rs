//! Bounded time of rotor discovery (issue #15, deliverable 5): wall time and eigen-solves of
//! `discover` on 8 modes of the paper rotor for the worst data we know — every draw at 0.2 %
//! noise of every case of the independent fixtures (each effect kind, the fine-mesh truth that
//! triggers the refined-mesh search), every clean draw at every noise level, and decimal-slip
//! outliers (one clean frequency × 10 or ÷ 10). Prints the worst per case.
//!
//! cargo run --release -p eigenfit-rotor --example discovery_timing

#[path = "../tests/common/study.rs"]
mod study;

use std::sync::atomic::Ordering;
use std::time::Instant;
use study::CountingSolver;

/// Draws of one case: (frequencies, standard deviations), Hz.
type Draws = Vec<(Vec<f64>, Vec<f64>)>;

fn main() {
    let fixtures = study::load();
    let mut cases: Vec<(String, Draws)> = Vec::new();
    for case in &fixtures.case {
        let draws: Vec<_> = fixtures
            .draw
            .iter()
            // Clean data at every noise level: a chance-significant misfit that nothing explains
            // runs the whole search again on the refined mesh, the costliest path there is.
            .filter(|d| d.case == case.name && (d.noise == 0.002 || case.name == "clean") && d.draw < 10)
            .map(|d| (d.frequency_hz.clone(), d.std_hz.clone()))
            .collect();
        cases.push((case.name.clone(), draws));
    }
    // A decimal slip in one mode of a clean draw (the std stays the file's).
    let clean = fixtures.draw.iter().find(|d| d.case == "clean" && d.noise == 0.001).expect("a clean draw");
    let slips: Vec<_> = [(4, 10.0), (4, 0.1), (7, 0.1), (1, 10.0)]
        .into_iter()
        .map(|(mode, factor)| {
            let mut f = clean.frequency_hz.clone();
            f[mode] *= factor;
            (f, clean.std_hz.clone())
        })
        .collect();
    cases.push(("decimal-slip".into(), slips));
    println!(
        "| data | runs | slowest wall [s] | most CPU [s] | most eigen-solves | most charged evaluations | budget exhausted |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut overall = 0.0f64;
    for (name, draws) in &cases {
        let (mut slowest, mut cpu, mut solves, mut charged, mut exhausted) = (0.0f64, 0.0f64, 0, 0, 0);
        for (f, s) in draws {
            let solver = CountingSolver::default();
            let (t, c) = (Instant::now(), cpu_seconds());
            // Measurement::new refuses frequencies out of order: such a slip never reaches discover.
            let found = std::panic::catch_unwind(|| study::run_counted(f, s, &solver));
            slowest = slowest.max(t.elapsed().as_secs_f64());
            cpu = cpu.max(cpu_seconds() - c);
            solves = solves.max(solver.solves.load(Ordering::Relaxed));
            if let Ok(found) = found {
                charged = charged.max(found.report.evaluations);
                exhausted += usize::from(found.report.budget_exhausted);
            }
        }
        overall = overall.max(cpu);
        println!(
            "| {name} | {} | {slowest:.3} | {cpu:.2} | {solves} | {charged} | {exhausted} |",
            draws.len()
        );
    }
    println!("\nmost CPU time of one run: {overall:.2} s");
}

/// CPU time of this thread (user + system), from /proc (Linux; 10 ms ticks): on a shared
/// machine the wall time measures the neighbours too.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    // (the first of them, the state, is field 3).
    let fields: Vec<&str> = after.split_whitespace().collect();
    let field = |n: usize| fields.get(n - 3).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    let ticks = field(14) + field(15);
    ticks / 100.0
}
