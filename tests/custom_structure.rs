//! The custom-structure example (issue 8) under test: its shear building, defined outside the
//! eigenfit crates, runs through every strategy; its 95% intervals hold the truth at the nominal
//! rate; its analytic derivative agrees with the core's finite difference; its model code stays
//! under 100 lines; discovery names the hidden storey mass.

#[path = "../examples/custom_structure.rs"]
#[allow(dead_code)]
mod example;

use eigenfit::core::model::{finite_difference_derivative, ModelError, StructuralModel};

use example::model::ShearBuilding;
use example::{
    building, chi2_95, discover_storey_mass, measurements, problems, update_all, Noise, Run, DESIGN,
    HIDDEN_MASS, MASSES, SEED, TRUTH,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

fn inside(run: &Run) -> Vec<bool> {
    let intervals = run.intervals.as_ref().expect("damped runs carry intervals");
    TRUTH.iter().zip(intervals).map(|(&t, &[lo, hi])| lo <= t && t <= hi).collect()
}

fn damped(runs: &[Run]) -> &Run {
    runs.iter().find(|r| r.strategy == "damped").expect("damped ran")
}

#[test]
fn model_code_is_under_100_lines() {
    let src = include_str!("../examples/custom_structure.rs");
    let begin = src.find("// --- model: begin").expect("begin marker");
    let end = src.find("// --- model: end").expect("end marker");
    let lines = src[begin..end].lines().count() - 1;
    assert!((20..100).contains(&lines), "the model section has {lines} lines");
}

#[test]
fn every_strategy_converges_on_clean_data() {
    let runs = update_all(&problems(measurements(false, None)));
    assert_eq!(runs.len(), 3);
    for run in &runs {
        let e = &run.estimate;
        assert!(e.termination.is_converged(), "{}: {}", run.strategy, e.termination);
        let err = e.parameters.iter().zip(TRUTH).map(|(k, t)| (k / t - 1.0).abs()).fold(0.0, f64::max);
        // Newton and p-step stop at 1e-4 Hz; damped fits to round-off.
        let tol = if run.strategy == "damped" { 1e-6 } else { 1e-3 };
        assert!(err < tol, "{}: relative error {err:e}", run.strategy);
    }
}

#[test]
fn damped_recovers_the_storey_stiffnesses_within_their_intervals() {
    let runs = update_all(&problems(measurements(false, Some(&mut Noise(SEED)))));
    let d = damped(&runs);
    assert!(d.estimate.termination.is_converged(), "{}", d.estimate.termination);
    assert!(inside(d).iter().all(|&h| h), "intervals {:?}", d.intervals);
    let (chi2, dof) = d.chi2;
    assert_eq!(dof, 10);
    assert!(chi2 < chi2_95(dof), "χ² {chi2} on {dof}");
    for run in &runs {
        assert!(run.estimate.termination.is_converged(), "{}", run.strategy);
    }
}

#[test]
fn the_hidden_mass_biases_the_stiffnesses_and_shows_in_chi2() {
    let runs = update_all(&problems(measurements(true, Some(&mut Noise(SEED)))));
    let d = damped(&runs);
    assert!(d.estimate.termination.is_converged(), "{}", d.estimate.termination);
    let (chi2, dof) = d.chi2;
    assert!(chi2 > chi2_95(dof), "χ² {chi2} on {dof}: the hidden mass must be detectable");
    assert!(inside(d).iter().any(|&h| !h), "the stiffnesses absorb the mass: some interval misses");
}

/// The example's seed is one draw; over 200 the intervals must hold at their nominal rate and the
/// hidden mass must show in χ² nearly always.
#[test]
fn interval_coverage_and_detection_rates_over_many_draws() {
    let draws = 200;
    let (mut covered, mut jointly, mut detected) = ([0usize; 5], 0, 0);
    for seed in 0..draws {
        let runs = update_all(&problems(measurements(false, Some(&mut Noise(seed)))));
        let hits = inside(damped(&runs));
        hits.iter().zip(&mut covered).for_each(|(&h, c)| *c += h as usize);
        jointly += hits.iter().all(|&h| h) as usize;
        let runs = update_all(&problems(measurements(true, Some(&mut Noise(seed)))));
        let (chi2, dof) = damped(&runs).chi2;
        detected += (chi2 > chi2_95(dof)) as usize;
    }
    let rate = |n: usize| n as f64 / draws as f64;
    for (i, &c) in covered.iter().enumerate() {
        assert!((0.88..=0.99).contains(&rate(c)), "k{}: coverage {}", i + 1, rate(c));
    }
    assert!(rate(jointly) >= 0.7, "joint coverage {}", rate(jointly));
    assert!(rate(detected) >= 0.95, "detection rate {}", rate(detected));
}

#[test]
fn chi2_threshold_matches_tables() {
    // Wilson–Hilferty against the tabulated 95% quantiles.
    for (dof, table) in [(5, 11.070), (10, 18.307), (25, 37.652)] {
        assert!((chi2_95(dof) / table - 1.0).abs() < 5e-3, "dof {dof}: {}", chi2_95(dof));
    }
}

#[test]
fn derivative_rejects_a_parameter_that_does_not_exist() {
    assert_eq!(
        building().derivative(&DESIGN, 5).unwrap_err(),
        ModelError::ParameterIndex { index: 5, count: 5 }
    );
}

proptest! {
    // Fixed seed, no regression file: the same cases on every run and machine.
    #![proptest_config(ProptestConfig {
        cases: 64,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(8),
        ..ProptestConfig::default()
    })]

    /// The analytic sparse derivative equals the core's central finite difference to 1e-6
    /// relative, on random buildings of 1–12 storeys at random points, and the mass derivative
    /// is empty in both. Storey stiffnesses stay within a factor of 3 of a common level and the
    /// point within a factor of 3 of the design, as in a real building: the finite difference's
    /// round-off, ε·|K|max/(1e-6·kᵢ), grows with the stiffness contrast, not the derivative's.
    #[test]
    fn analytic_derivative_equals_finite_difference(
        storeys in (1usize..=12).prop_flat_map(|n| (
            prop::collection::vec(1e3..1e6f64, n),
            5.0..9.0f64,
            prop::collection::vec(-0.5..0.5f64, n),
            prop::collection::vec(-0.5..0.5f64, n),
        ))
    ) {
        let (masses, level, spread, offsets) = storeys;
        let design: Vec<f64> = spread.iter().map(|s| 10f64.powf(level + s)).collect();
        let b = ShearBuilding::new(&masses, &design).unwrap();
        let p: Vec<f64> = design.iter().zip(&offsets).map(|(k, o)| k * 10f64.powf(*o)).collect();
        for i in 0..design.len() {
            let exact = b.derivative(&p, i).unwrap();
            let fd = finite_difference_derivative(&b, &p, i).unwrap();
            let (e, f) = (exact.stiffness.to_dense(), fd.stiffness.to_dense());
            let err = (&e - &f).amax() / e.amax();
            prop_assert!(err < 1e-6, "∂K/∂k{}: relative error {err:e}", i + 1);
            prop_assert!(exact.mass.is_empty() && fd.mass.is_empty(), "∂M/∂k{} must be empty", i + 1);
        }
    }
}

#[test]
fn discovery_names_the_hidden_storey_mass() {
    let report = discover_storey_mass(&measurements(true, Some(&mut Noise(SEED))));
    assert!(report.before.significant);
    let fit = report.selected.expect("an effect is named");
    // Storey 3 (floor index 2), +30% of its mass.
    assert_eq!((fit.kind.as_str(), fit.location), ("added-storey-mass", Some(3)));
    let [lo, hi] = fit.interval.unwrap();
    let truth = HIDDEN_MASS.1 / MASSES[HIDDEN_MASS.0];
    assert!(lo <= truth && truth <= hi, "{truth} outside [{lo}, {hi}]");
    // Without the hidden mass nothing is added.
    let report = discover_storey_mass(&measurements(false, Some(&mut Noise(SEED))));
    assert!(report.selected.is_none());
}
