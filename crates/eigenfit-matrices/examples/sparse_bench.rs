//! Times one matrices model: reading the files, assembling K(p), M(p), and the lowest modes with
//! their sensitivities (sparse solver), printing one JSON line. Driven by
//! `scripts/bench_sparse.py`, which runs scipy's `eigsh` on the same files for comparison.
//!
//! ```text
//! cargo run --release -p eigenfit-matrices --example sparse_bench -- MODEL.toml [MODES]
//! ```

use eigenfit_core::eigen::{EigenSolver, SparseSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::sensitivity::Sensitivities;
use eigenfit_matrices::MatricesModel;
use std::time::Instant;

/// CPU seconds of this (single-threaded) process so far, from /proc/self/schedstat (ns): on a
/// shared machine wall time measures the neighbours as much as the work.
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|v| v.parse::<f64>().ok()))
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: sparse_bench MODEL.toml [MODES]");
    let modes: usize = args.next().map_or(10, |m| m.parse().expect("MODES is a number"));
    let (t, c) = (Instant::now(), cpu_s());
    let model = MatricesModel::from_toml_file(path.as_ref()).unwrap_or_else(|e| panic!("{e}"));
    let load_s = t.elapsed().as_secs_f64();
    let load_cpu_s = cpu_s() - c;
    let p = model.parameters().nominal_values();
    let t = Instant::now();
    let system = model.assemble(&p).expect("assembles");
    let assemble_s = t.elapsed().as_secs_f64();
    let solver = SparseSolver::default();
    // Cold: modes + sensitivities in one call (assembly, ordering, factor, Lanczos, Sturm count),
    // as `simulate` does; the headline number.
    let (t, c) = (Instant::now(), cpu_s());
    let sens = Sensitivities::compute(&model, &solver, &p, modes).expect("sensitivities");
    let with_sensitivities_s = t.elapsed().as_secs_f64();
    let with_sensitivities_cpu_s = cpu_s() - c;
    // Warm: the modes again with the symbolic factorisation kept, as every update iteration.
    let (t, c) = (Instant::now(), cpu_s());
    let (found, next) = solver.lowest_with_next(&system, modes).expect("solves");
    let modes_s = t.elapsed().as_secs_f64();
    let modes_cpu_s = cpu_s() - c;
    let peak_kb = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(|l| l.split_whitespace().nth(1).unwrap_or("0").parse::<u64>().unwrap_or(0))
        })
        .unwrap_or(0);
    let df: Vec<Vec<f64>> = (0..sens.frequencies_hz.ncols())
        .map(|i| sens.frequencies_hz.column(i).iter().copied().collect())
        .collect();
    println!(
        "{{\"dofs\": {}, \"nnz\": {}, \"load_s\": {load_s}, \"load_cpu_s\": {load_cpu_s}, \"assemble_s\": {assemble_s}, \"warm_modes_s\": {modes_s}, \"warm_modes_cpu_s\": {modes_cpu_s}, \"modes_and_sensitivities_s\": {with_sensitivities_s}, \"modes_and_sensitivities_cpu_s\": {with_sensitivities_cpu_s}, \"sturm_bound\": {next}, \"peak_rss_kb\": {peak_kb}, \"frequencies_hz\": {:?}, \"sensitivities_hz\": {:?}}}",
        model.dofs(),
        model.nnz(),
        found.frequencies_hz(),
        df
    );
}
