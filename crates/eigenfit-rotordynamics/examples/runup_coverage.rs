//! Interval coverage of the run-up estimate over noise draws (issue 16), and the clean-data
//! verdict: how often the true kxx, kyy lie inside the 95 % intervals `estimate` reports, and how
//! often the calibrated fit's χ² test (and, with `discover`, discovery) calls clean data
//! significant.
//!
//! The truth is ROSS's noise-free run-up of `runup_nominal.toml` (`coverage_nominal.csv`, made
//! by scripts/ross_coverage_runup.py: 6 modes at 6 speeds); each draw adds Gaussian noise of the
//! file's std_hz (0.02 Hz, seeded) and estimates the four bearing stiffnesses from a start 20 %
//! off (factors 1.2, 0.8, 0.8, 1.2), as `estimate` does (refits from screened starts
//! included). Truth: every factor 1. The noise-free
//! run-up is also fitted from a start 35–45 % off (1.4, 0.6, 0.65, 1.45), to show whether the
//! estimate's basin reaches that far on this rotor.
//!
//! `cargo run --release -p eigenfit-rotordynamics --example runup_coverage -- [DRAWS] [discover]`
use eigenfit_core::analysis::{chi2_upper_tail, uncertainty};
use eigenfit_core::discovery::{discover_effects, DiscoveryOptions};
use eigenfit_core::measurement::synthetic::NoiseRng;
use eigenfit_core::update::{Budget, Estimate};
use eigenfit_rotordynamics::effects::candidates;
use eigenfit_rotordynamics::fit::fit_runup;
use eigenfit_rotordynamics::identify::Parameter;
use eigenfit_rotordynamics::identify::{read_runup, stiffness_parameters, RunupPoint};
use eigenfit_rotordynamics::objective::{RunupObjective, RunupSearch, DISCOVERY_FACTOR_RANGE};
use eigenfit_rotordynamics::Rotor;
use std::path::Path;

/// The run-up estimate as `estimate` makes it (core's driver with restarts from screened
/// starts): the estimate, the restarts taken and σ(ln s) from core's covariance.
fn estimate(
    rotor: &Rotor,
    params: &[Parameter],
    points: &[RunupPoint],
    start: &[f64],
) -> (Estimate, usize, Vec<f64>) {
    let objective = RunupObjective::new(rotor, params.to_vec(), points, None).expect("objective");
    let (est, restarts) =
        fit_runup(&objective, params, start, 100, REFITS, &Budget::unlimited()).expect("fit");
    let u = uncertainty(&objective, &est.last).expect("std_hz given: intervals");
    let sd = (0..params.len()).map(|i| u.covariance[(i, i)].sqrt() / est.parameters[i]).collect();
    (est, restarts, sd)
}

const START: [f64; 4] = [1.2, 0.8, 0.8, 1.2];
const FAR_START: [f64; 4] = [1.4, 0.6, 0.65, 1.45];
const SEED: u64 = 1616;
/// As `estimate`'s default `--alternative-starts`.
const REFITS: usize = 6;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let draws: usize = args.get(1).map_or(40, |a| a.parse().expect("DRAWS: a whole number"));
    let with_discovery = args.iter().any(|a| a == "discover");
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let rotor = eigenfit_rotordynamics::ross_file::read(&data.join("runup_nominal.toml")).expect("rotor");
    let exact = read_runup(&data.join("coverage_nominal.csv")).expect("run-up");
    let params = stiffness_parameters(&rotor);
    assert_eq!(params.len(), START.len(), "runup_nominal.toml has two bearings");
    let dof = exact.len() - params.len();

    // Noise-free: the estimate should return the truth (ROSS and eigenfit agree to ~1e-6).
    for (what, start) in [("20 % off", START), ("35–45 % off", FAR_START)] {
        let (id, restarts, _) = estimate(&rotor, &params, &exact, &start);
        let worst = id.parameters.iter().map(|s| (s - 1.0).abs()).fold(0.0, f64::max);
        println!(
            "noise-free, start {what}: {}, largest |factor − 1| {worst:.2e}, χ² {:.2e} (std 0.02 Hz), {restarts} restarts, {} evaluations",
            id.termination, id.last.chi2(), id.evaluations
        );
    }

    let mut rng = NoiseRng(SEED);
    let mut covered = vec![0usize; params.len()];
    let (mut all_covered, mut converged, mut significant, mut evaluations) = (0, 0, 0, 0);
    let (mut named, mut discovery_significant, mut discovery_evaluations) = (0, 0, 0);
    let mut z_sum = vec![0.0; params.len()];
    let mut z2_sum = vec![0.0; params.len()];
    for _ in 0..draws {
        let noisy: Vec<RunupPoint> = exact
            .iter()
            .map(|p| RunupPoint {
                frequency_hz: p.frequency_hz + p.std_hz.unwrap() * rng.normal(),
                ..p.clone()
            })
            .collect();
        let (id, _, sd) = estimate(&rotor, &params, &noisy, &START);
        evaluations += id.evaluations;
        converged += usize::from(id.termination.is_converged());
        let mut all = true;
        for (k, (s, sd)) in id.parameters.iter().zip(&sd).enumerate() {
            // The reported interval is k·exp(±1.96·sd) in ln k: the truth (factor 1) is inside
            // when |ln s| ≤ 1.96·sd.
            let z = s.ln() / sd;
            z_sum[k] += z;
            z2_sum[k] += z * z;
            let inside = z.abs() <= 1.96;
            covered[k] += usize::from(inside);
            all &= inside;
        }
        all_covered += usize::from(all);
        significant += usize::from(chi2_upper_tail(id.last.chi2(), dof) < 0.05);
        if with_discovery {
            let (lower, upper) = DISCOVERY_FACTOR_RANGE;
            let base = RunupObjective::new(&rotor, params.clone(), &noisy, None)
                .and_then(|o| o.within(lower, upper))
                .expect("objective");
            let effects = candidates(&rotor);
            let search = RunupSearch::new(base, &effects);
            let r = discover_effects(&search, &search.candidates(), &[1.0; 4], &DiscoveryOptions::default())
                .expect("discovery");
            named += usize::from(!r.effects.is_empty());
            discovery_significant += usize::from(r.before.significant);
            discovery_evaluations += r.evaluations;
        }
    }
    let pct = |k: usize| 100.0 * k as f64 / draws as f64;
    println!("{draws} draws (seed {SEED}), std 0.02 Hz, 36 frequencies, {dof} dof; {converged} converged, {:.0} evaluations per fit", evaluations as f64 / draws as f64);
    println!("| parameter | truth inside its 95 % interval | mean z | std z |");
    println!("|---|---|---|---|");
    for (k, p) in params.iter().enumerate() {
        let mean = z_sum[k] / draws as f64;
        let sd = (z2_sum[k] / draws as f64 - mean * mean).max(0.0).sqrt();
        println!("| {} | {}/{draws} ({:.0} %) | {mean:+.2} | {sd:.2} |", p.name, covered[k], pct(covered[k]));
    }
    println!("| all four at once | {all_covered}/{draws} ({:.0} %) | | |", pct(all_covered));
    println!("χ² test of the fit significant at 5 %: {significant}/{draws} ({:.1} %)", pct(significant));
    if with_discovery {
        println!(
            "discover: misfit significant {discovery_significant}/{draws}, an effect named {named}/{draws}, {:.0} evaluations per run",
            discovery_evaluations as f64 / draws as f64
        );
    }
}
