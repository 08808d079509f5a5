//! A library consumer's 5-parameter truss (issue 13: "`discover` killed after 29 minutes"):
//! a planar four-bay Pratt truss whose member groups' axial stiffnesses EA are the parameters,
//! updated from noisy measured frequencies with 95 % intervals, then searched for a missing
//! effect — every step within one evaluation budget, ending in an answer or a verdict.
//!
//! Run: `cargo run --release -p eigenfit-core --example five_group_truss`
//! (tests/truss_budget.rs runs the same code and counts its evaluations; scripts/bench_trust.py
//! times it).

use eigenfit_core::analysis::uncertainty_within;
use eigenfit_core::discovery::{discover, DiscoveryError, DiscoveryOptions, DiscoveryReport};
use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::measurement::synthetic::NoiseRng;
use eigenfit_core::measurement::{MeasuredMode, Measurement};
pub use eigenfit_core::model::truss::{Truss, DESIGN, GROUPS, TRUTH};
use eigenfit_core::model::StructuralModel;
use eigenfit_core::problem::Problem;
use eigenfit_core::update::{Budget, Driver, Estimate, LevenbergMarquardt};

/// Frequencies measured (the lowest).
pub const MODES: usize = 8;
/// Relative standard deviation of a measured frequency.
pub const NOISE: f64 = 2e-3;
/// Seed of the measurement noise: a draw in which all five 95 % intervals hold (seeds 1–8:
/// seven hold all five, two hold four of five — about what 95 % intervals promise).
pub const SEED: u64 = 1;
/// The hidden effect: 200 kg (θ = 0.5 of the node's 400 kg) at mid-span node B2.
pub const HIDDEN_KG: f64 = 200.0;

/// The measured truss: `TRUTH`, plus `hidden` kg at node B2 (mid-span), noise from `seed`.
pub fn measurement(hidden: f64, seed: u64) -> Measurement {
    let mut real = Truss::new();
    real.extra_mass[2] = hidden;
    let f =
        DenseSolver.lowest(&real.assemble(&TRUTH).expect("truth"), MODES).expect("solvable").frequencies_hz();
    let mut noise = NoiseRng(seed);
    let modes = f
        .iter()
        .enumerate()
        .map(|(k, &f)| MeasuredMode::new(k, f * (1.0 + NOISE * noise.normal())).with_std(NOISE * f));
    Measurement::new(modes.collect()).expect("valid measurement")
}

/// An estimate with its 95 % intervals (`None` when the budget ran out first).
pub struct Fitted {
    /// The damped least-squares estimate.
    pub estimate: Estimate,
    /// 95 % intervals per group.
    pub intervals: Option<Vec<[f64; 2]>>,
    /// True when the budget ran out while the intervals were computed (they are then incomplete).
    pub intervals_cut: bool,
}

/// Estimate and intervals from the design values, all charged to `budget`.
pub fn estimate(measured: &Measurement, budget: &Budget) -> Fitted {
    let problem = Problem::new(Truss::new(), DenseSolver, measured.clone());
    let estimate = Driver::default()
        .run_within(&problem, &mut LevenbergMarquardt::default(), &DESIGN, budget)
        .expect("the fit runs");
    let u = uncertainty_within(&problem, &estimate.last, budget);
    let intervals_cut = u.as_ref().is_some_and(|u| u.budget_exhausted);
    Fitted { estimate, intervals: u.map(|u| u.intervals), intervals_cut }
}

/// `discover` on the truss with at most `budget` evaluations.
pub fn discover_within(measured: &Measurement, budget: usize) -> Result<DiscoveryReport, DiscoveryError> {
    let truss = Truss::new();
    let options = DiscoveryOptions { max_evaluations: budget, ..Default::default() };
    discover(&truss, &DenseSolver, measured, &truss.candidates(), &DESIGN, &options)
}

#[allow(dead_code)] // the test includes this file for its model and runs
fn main() {
    const BUDGET: usize = 10_000;
    for (label, hidden) in
        [("as designed", 0.0), ("with 200 kg at mid-span", HIDDEN_KG), ("with 600 kg at mid-span", 600.0)]
    {
        let measured = measurement(hidden, SEED);
        let budget = Budget::new(BUDGET);
        let fit = estimate(&measured, &budget);
        println!("{label}: estimate {:?} after {} evaluations", fit.estimate.termination, budget.used());
        for (i, name) in GROUPS.iter().enumerate() {
            let iv = fit.intervals.as_ref().map_or(String::from("no interval"), |iv| {
                format!("95% [{:.3e}, {:.3e}]", iv[i][0], iv[i][1])
            });
            println!("  {name} = {:.4e} N ({iv}), truth {:.4e}", fit.estimate.last.parameters[i], TRUTH[i]);
        }
        let report = match discover_within(&measured, BUDGET) {
            Ok(report) => report,
            Err(e) => {
                println!("  discover: {e}");
                continue;
            }
        };
        let named: Vec<String> = report
            .effects
            .iter()
            .map(|e| format!("{} = {:?}, 95% {:?}", e.place.label, e.value, e.interval))
            .collect();
        println!(
            "  discover: χ² {:.2} on {} dof, p = {:.3e}, named {named:?}, {} evaluations, budget exhausted: {}",
            report.before.chi2, report.before.dof, report.before.p_value, report.evaluations, report.budget_exhausted
        );
    }
}
