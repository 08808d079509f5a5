//! Issue 13's library consumer: a 5-parameter truss whose `discover` was killed after 29 minutes.
//! The same model and runs as `examples/five_group_truss.rs`: the estimate with its intervals,
//! and the discovery, each end in an answer or a verdict within the evaluation budget it was
//! given. Bounded work is asserted by counting evaluations (no timing: the machine is shared).

#[path = "../examples/five_group_truss.rs"]
mod truss;

use eigenfit_core::discovery::DiscoveryError;
use eigenfit_core::update::{Budget, Termination};
use truss::{GROUPS, TRUTH};

#[test]
fn the_truss_estimate_and_its_intervals_stay_within_the_budget_and_hold_the_truth() {
    let measured = truss::measurement(0.0, truss::SEED);
    let budget = Budget::new(5_000);
    let fit = truss::estimate(&measured, &budget);
    assert!(budget.used() <= 5_000 && !budget.exhausted(), "{} evaluations", budget.used());
    assert!(fit.estimate.termination.is_converged(), "{:?}", fit.estimate.termination);
    let intervals = fit.intervals.expect("intervals with std given");
    for (i, name) in GROUPS.iter().enumerate() {
        let [lo, hi] = intervals[i];
        assert!(lo < TRUTH[i] && TRUTH[i] < hi, "{name}: truth {} outside [{lo}, {hi}]", TRUTH[i]);
    }
}

#[test]
fn a_small_budget_ends_the_truss_estimate_with_a_verdict_not_a_hang() {
    let measured = truss::measurement(truss::HIDDEN_KG, truss::SEED);
    let budget = Budget::new(40);
    let fit = truss::estimate(&measured, &budget);
    assert!(budget.used() <= 40, "{} evaluations", budget.used());
    assert!(budget.exhausted(), "40 evaluations cannot fit and bound five parameters");
    // The verdict says so: the fit, or else its intervals, are marked cut short.
    let cut = matches!(fit.estimate.termination, Termination::BudgetExhausted { .. });
    assert!(cut || fit.intervals_cut, "{:?}", fit.estimate.termination);
}

#[test]
fn the_truss_discovery_names_the_hidden_mass_within_its_budget() {
    let measured = truss::measurement(truss::HIDDEN_KG, truss::SEED);
    let report = truss::discover_within(&measured, 10_000).expect("discovery runs");
    assert!(report.evaluations <= 10_000, "{} evaluations", report.evaluations);
    assert!(report.before.significant, "χ² {} on {} dof", report.before.chi2, report.before.dof);
    assert!(!report.budget_exhausted);
    let first = report.effects.first().expect("an effect named");
    assert_eq!(
        (first.place.kind.as_str(), first.place.location),
        ("added-node-mass", Some(2)),
        "{:?}",
        report.effects
    );
    // θ = 200 kg / 400 kg; the noise moves it by a few per cent.
    let theta = first.value.expect("a mass has a value");
    assert!((theta - 0.5).abs() < 0.1, "θ = {theta}");
}

/// A mass so large that the calibration without it runs a group to its limit: no candidate then
/// explains the data, and the search says so (a verdict, exit 3 in the CLI) within its budget.
#[test]
fn a_truss_too_far_from_its_model_ends_in_a_verdict_within_the_budget() {
    let measured = truss::measurement(600.0, truss::SEED);
    let report = truss::discover_within(&measured, 10_000).expect("discovery runs");
    assert!(report.evaluations <= 10_000, "{} evaluations", report.evaluations);
    assert!(report.before.significant);
    // Either the right answer or none: never a wrong place.
    assert!(
        report.effects.iter().all(|e| e.place.location == Some(2)),
        "{:?}",
        report.effects.iter().map(|e| &e.place.label).collect::<Vec<_>>()
    );
}

#[test]
fn the_truss_discovery_with_a_small_budget_stops_and_says_so() {
    let measured = truss::measurement(truss::HIDDEN_KG, truss::SEED);
    for budget in [20, 150, 400] {
        match truss::discover_within(&measured, budget) {
            // Cut short in the search: what it had, marked so, nothing named on a partial search.
            Ok(report) => {
                assert!(report.evaluations <= budget, "{} evaluations for {budget}", report.evaluations);
                assert!(report.budget_exhausted, "budget {budget}: {} evaluations", report.evaluations);
            }
            // Cut short in the calibration: an error that says so.
            Err(e) => assert!(matches!(e, DiscoveryError::BudgetExhausted(b) if b == budget), "{e}"),
        }
    }
}

/// Discovery's calibration and candidate refits made by another registered strategy
/// (`DiscoveryOptions::refit`, issue 27 item 6): the trust-region strategy names the same hidden
/// mass at the same place within the same budget.
#[test]
fn the_truss_discovery_runs_on_a_refit_strategy_of_the_users_choice() {
    use eigenfit_core::discovery::{discover, DiscoveryOptions};
    use eigenfit_core::eigen::DenseSolver;
    use eigenfit_core::model::StructuralModel;
    use eigenfit_core::update::refit::{RefitChoice, Registered};
    let measured = truss::measurement(truss::HIDDEN_KG, truss::SEED);
    let refit = RefitChoice(std::sync::Arc::new(Registered::new("trf").unwrap()));
    let options = DiscoveryOptions { max_evaluations: 10_000, refit, ..Default::default() };
    let model = truss::Truss::new();
    let report =
        discover(&model, &DenseSolver, &measured, &model.candidates(), &truss::DESIGN, &options).unwrap();
    assert!(!report.budget_exhausted, "{} evaluations", report.evaluations);
    let first = report.effects.first().expect("an effect named");
    assert_eq!((first.place.kind.as_str(), first.place.location), ("added-node-mass", Some(2)));
    assert!((first.value.unwrap() - 0.5).abs() < 0.1, "θ = {:?}", first.value);
}
