//! Discovery on data it did not make (issue #15): frequencies from an independent numpy
//! finite-element code (`tests/fixtures/discovery/generate.py`), scored per case. The full study
//! (every draw) is `cargo run --release -p eigenfit-rotor --example discovery_study`; this test
//! runs a subset that stays within a minute in debug builds, and holds each case to what the
//! study measured (docs/discovery.md).

mod common;

use common::study::{self, Outcome};
use eigenfit_core::eigen::{BandedSolver, EigenSolver};
use eigenfit_core::model::{finite_difference_derivative, Augmented, StructuralModel};
use eigenfit_rotor::presets;

/// Runs `draws` draws of `case` at 0.1 % noise; counts (named or honestly ambiguous, wrong, nothing).
fn outcomes(case: &str, draws: usize) -> Vec<Outcome> {
    let fixtures = study::load();
    let expect = &fixtures.case.iter().find(|c| c.name == case).expect("case in the fixtures").expect;
    fixtures
        .draw
        .iter()
        .filter(|d| d.case == case && d.noise == 0.001 && d.draw < draws)
        .map(|d| study::score(expect, &study::run(d)).0)
        .collect()
}

fn hits(o: &[Outcome]) -> usize {
    o.iter().filter(|x| matches!(x, Outcome::Named | Outcome::Ambiguous)).count()
}

#[test]
fn no_false_alarm_on_clean_independent_data() {
    let o = outcomes("clean", 10);
    assert_eq!(o.len(), 10);
    assert!(o.iter().all(|x| *x == Outcome::Nothing), "{o:?}");
}

#[test]
fn names_every_in_list_effect_of_independent_data() {
    for case in [
        "disk-inertia",
        "mass-at-node",
        "mass-between-nodes",
        "bearing-mass",
        "crack",
        "shear",
        "timoshenko",
        "thin-element",
        "thin-run",
        "two-effects",
        "taper",
    ] {
        let o = outcomes(case, 2);
        assert_eq!(hits(&o), o.len(), "{case}: {o:?}");
    }
}

#[test]
fn names_a_pedestal_under_either_bearing() {
    for case in ["pedestal", "pedestal-k1"] {
        let o = outcomes(case, 2);
        assert_eq!(hits(&o), o.len(), "{case}: {o:?}");
    }
}

/// The mesh error the overall χ² lets pass is still found: held-out fine-mesh draw 1 at 0.2 %
/// noise (χ² not significant at 5 %) is explained by the refined mesh, which is named.
#[test]
fn names_the_refined_mesh_when_the_overall_test_lets_its_error_pass() {
    let fixtures = study::load_heldout();
    let draw =
        fixtures.draw.iter().find(|d| d.case == "fine-mesh" && d.noise == 0.002 && d.draw == 1).unwrap();
    let found = study::run_counted(&draw.frequency_hz, &draw.std_hz, &Default::default());
    assert!(!found.report.before.significant, "p = {}", found.report.before.p_value);
    let kinds: Vec<&str> = found.effects.iter().map(|e| e.kind.as_str()).collect();
    assert_eq!(kinds, ["mesh-refinement"]);
    assert_eq!(found.mesh_factor, eigenfit_rotor::discovery::REFINEMENT);
}

/// A thin element the data cannot tell from a taper around it: held-out thin-element draw 2 at
/// 0.2 % noise, where a taper fits best, lists the step itself as an equally good answer (it was
/// not even refitted before the leader's neighbours were).
#[test]
fn a_step_the_data_cannot_tell_from_a_taper_is_listed_beside_it() {
    assert_step_listed(&study::load_heldout(), 2);
}

/// The same when the taper that fits best shares no element with the step (elements 2–3 against
/// element 5; seed 60411, 0.2 % noise): the step was refitted only once look-alike predictions,
/// not overlapping places, chose the refits, and it trails the taper by ΔAICc 5.4 — listed
/// because the taper is the best of many fits compared (the Bonferroni margin).
#[test]
fn a_step_is_listed_beside_a_taper_elsewhere_that_predicts_alike() {
    assert_step_listed(&study::load_fresh(), 3);
}

/// Thin-element draw `draw` at 0.2 % noise: right or honestly ambiguous, with the uniform step
/// at element 5 named or listed beside the first effect.
fn assert_step_listed(fixtures: &study::Fixtures, draw: usize) {
    let draw = fixtures
        .draw
        .iter()
        .find(|d| d.case == "thin-element" && d.noise == 0.002 && d.draw == draw)
        .unwrap();
    let named = study::run(draw);
    let expect = &fixtures.case.iter().find(|c| c.name == "thin-element").unwrap().expect;
    assert!(matches!(study::score(expect, &named).0, Outcome::Named | Outcome::Ambiguous), "{named:?}");
    let first = &named[0];
    let step = |p: &eigenfit_core::discovery::Place| p.elements == Some([5, 5]) && p.taper_to.is_none();
    assert!(step(first) || first.ambiguous_with.iter().any(|a| step(a)), "{first:?}");
}

/// The pedestal candidate (one DOF more, the bearing spring re-routed) at the generator's truth
/// gives the generator's frequencies: the numpy code assembled its pedestal on its own.
#[test]
fn pedestal_candidate_reproduces_the_independent_pedestal_rotor() {
    let rotor = presets::paper_rotor();
    let fixtures = study::load();
    for (case, bearing, mass, stiffness) in [("pedestal", 1, 0.5, 2e6), ("pedestal-k1", 0, 0.8, 5e6)] {
        let exact = &fixtures.case.iter().find(|c| c.name == case).unwrap().exact_hz;
        let candidates = eigenfit_rotor::pedestal::candidates(&rotor, rotor.total_mass());
        let model = Augmented::new(&rotor, &candidates[bearing]).unwrap();
        assert_eq!(model.dofs(), rotor.dofs() + 1);
        let system = model.assemble(&[2e5, 5e4, mass, stiffness]).unwrap();
        let f = BandedSolver::default().lowest(&system, exact.len()).unwrap().frequencies_hz();
        for (m, (a, b)) in f.iter().zip(exact).enumerate() {
            assert!((a - b).abs() <= 1e-8 * b, "{case} mode {m}: {a} vs numpy {b}");
        }
    }
}

/// The taper candidate at the generator's truth (Ø14 → Ø11 mm linearly over elements 5–7) gives
/// the generator's frequencies: numpy integrated its tapered elements on its own.
#[test]
fn taper_candidate_reproduces_the_independent_taper_rotor() {
    let rotor = presets::paper_rotor();
    let fixtures = study::load();
    let exact = &fixtures.case.iter().find(|c| c.name == "taper").unwrap().exact_hz;
    let candidates = eigenfit_rotor::effects::candidates(&rotor);
    let taper = candidates.iter().find(|c| c.label() == "section-change@5-7~7").expect("the taper");
    let model = Augmented::new(&rotor, taper).unwrap();
    let system = model.assemble(&[2e5, 5e4, 11.0 / 14.0 - 1.0]).unwrap();
    let f = BandedSolver::default().lowest(&system, exact.len()).unwrap().frequencies_hz();
    for (m, (a, b)) in f.iter().zip(exact).enumerate() {
        assert!((a - b).abs() <= 1e-8 * b, "taper mode {m}: {a} vs numpy {b}");
    }
    // Its derivative (a sum of graded parts) matches finite differences.
    let p = [2e5, 5e4, -0.2];
    let exact = model.derivative(&p, 2).unwrap();
    let fd = finite_difference_derivative(&model, &p, 2).unwrap();
    for (a, b) in [(&exact.stiffness, &fd.stiffness), (&exact.mass, &fd.mass)] {
        let (a, b) = (a.to_dense(), b.to_dense());
        let scale = a.amax();
        assert!((a - b).amax() <= 1e-6 * scale, "taper: analytic vs finite-difference derivative");
    }
}

#[test]
fn pedestal_derivatives_match_finite_differences() {
    let rotor = presets::paper_rotor();
    let candidates = eigenfit_rotor::pedestal::candidates(&rotor, rotor.total_mass());
    for c in &candidates {
        let model = Augmented::new(&rotor, c).unwrap();
        let p = [2e5, 5e4, 0.5, 2e6];
        // Both bearing stiffnesses (one of them re-routed), the pedestal mass and stiffness.
        for i in 0..4 {
            let exact = model.derivative(&p, i).unwrap();
            let fd = finite_difference_derivative(&model, &p, i).unwrap();
            for (a, b) in [(&exact.stiffness, &fd.stiffness), (&exact.mass, &fd.mass)] {
                let (a, b) = (a.to_dense(), b.to_dense());
                let scale = a.amax().max(1.0);
                assert!((a - b).amax() <= 1e-6 * scale, "{} parameter {i}", c.label());
            }
        }
    }
}

#[test]
fn candidate_derivatives_match_finite_differences() {
    let rotor = presets::paper_rotor();
    let candidates = eigenfit_rotor::effects::candidates(&rotor);
    for kind in
        ["section-change", "point-mass", "shaft-rotary-inertia", "timoshenko-shaft", "shaft-stiffness-loss"]
    {
        // (A switch at the textbook value has no value to differentiate.)
        for c in candidates.iter().filter(|c| c.kind == kind && c.parameter.is_some()).take(3) {
            let model = Augmented::new(&rotor, c).unwrap();
            let mut p = vec![2e5, 5e4];
            // A value away from 0, where a non-linear law differs from its tangent at 0.
            p.push(if kind == "section-change" { -0.2 } else { 0.3 });
            let exact = model.derivative(&p, 2).unwrap();
            let fd = finite_difference_derivative(&model, &p, 2).unwrap();
            for (a, b) in [(&exact.stiffness, &fd.stiffness), (&exact.mass, &fd.mass)] {
                let (a, b) = (a.to_dense(), b.to_dense());
                let scale = a.amax().max(1e-30);
                assert!(
                    (a - b).amax() <= 1e-6 * scale,
                    "{}: analytic vs finite-difference derivative",
                    c.label()
                );
            }
        }
    }
}

/// Bounded time without a timed assertion: every eigen-solve of a rotor discovery (user's mesh
/// and refined mesh together) is charged to one budget, so the solves counted at the solver never
/// exceed it — on the data that costs most (two effects, the fine-mesh truth that triggers the
/// refined-mesh search, a decimal slip).
#[test]
fn discovery_work_is_bounded_whatever_the_data() {
    use eigenfit_core::discovery::DEFAULT_EVALUATIONS;
    use std::sync::atomic::Ordering;
    let fixtures = study::load();
    let draw = |case: &str| {
        let d = fixtures.draw.iter().find(|d| d.case == case && d.noise == 0.002).unwrap();
        (d.frequency_hz.clone(), d.std_hz.clone())
    };
    let (mut slip, slip_std) = draw("clean");
    slip[4] *= 10.0; // 998 Hz typed as 9980 Hz
    for (name, (f, s)) in
        [("two-effects", draw("two-effects")), ("fine-mesh", draw("fine-mesh")), ("slip", (slip, slip_std))]
    {
        let solver = study::CountingSolver::default();
        let found = study::run_counted(&f, &s, &solver);
        let solves = solver.solves.load(Ordering::Relaxed);
        assert!(solves > 0 && solves <= DEFAULT_EVALUATIONS, "{name}: {solves} solves");
        assert_eq!(solves, found.report.evaluations, "{name}: every solve is charged to the budget");
    }
}

/// Issue #31: the search spent its budget refitting many candidates before it confirmed a leader
/// (a point mass between two nodes, two effects at once: ≥ 2856 and ≥ 6420 solves on these
/// draws before). The screen's leaders are now refitted locally, each round within its share,
/// so both are named — with nothing left unconfirmed — within budgets the old search could not
/// finish in; every solve is counted at the solver and accounted to a phase.
#[test]
fn a_mass_between_nodes_and_two_effects_are_confirmed_within_small_budgets() {
    use std::sync::atomic::Ordering;
    let fixtures = study::load();
    for (case, budget) in [("mass-between-nodes", 2000), ("two-effects", 5500)] {
        let draw = fixtures.draw.iter().find(|d| d.case == case && d.noise == 0.001 && d.draw == 0).unwrap();
        let case_def = fixtures.case.iter().find(|c| c.name == case).unwrap();
        let solver = study::CountingSolver::default();
        let options =
            eigenfit_core::discovery::DiscoveryOptions { max_evaluations: budget, ..Default::default() };
        let found = study::run_with(&draw.frequency_hz, &draw.std_hz, &solver, &options);
        let r = &found.report;
        assert!(!r.budget_exhausted, "{case}: budget of {budget} ran out: {:?}", r.spending);
        let (outcome, _) = study::score(&case_def.expect, &found.effects);
        assert_eq!(outcome, Outcome::Named, "{case}: {:?}", found.effects);
        let solves = solver.solves.load(Ordering::Relaxed);
        assert_eq!(solves, r.evaluations, "{case}: every solve is charged");
        assert!(solves <= budget, "{case}: {solves} solves");
        let s = r.spending;
        let phases = s.data_check
            + s.calibration
            + s.screening
            + s.refits
            + s.confirmation
            + s.carried
            + s.refined_mesh;
        assert_eq!(phases, r.evaluations, "{case}: every solve belongs to a phase: {s:?}");
        assert!(s.screening > 0 && s.refits > 0, "{case}: {s:?}");
    }
}
