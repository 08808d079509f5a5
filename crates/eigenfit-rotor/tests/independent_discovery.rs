//! Discovery on data it did not make (issue #15): frequencies from an independent numpy
//! finite-element code (`tests/fixtures/discovery/generate.py`), scored per case. The full study
//! (every draw) is `cargo run --release -p eigenfit-rotor --example discovery_study`; this test
//! runs a subset that stays within a minute in debug builds, and holds each case to what the
//! study measured (docs/discovery.md).

mod common;

use common::study::{self, Outcome};
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
    ] {
        let o = outcomes(case, 2);
        assert_eq!(hits(&o), o.len(), "{case}: {o:?}");
    }
}

#[test]
fn says_nothing_about_a_pedestal_it_has_no_candidate_for() {
    let o = outcomes("pedestal", 2);
    assert!(o.iter().all(|x| *x == Outcome::Nothing), "{o:?}");
}

#[test]
fn candidate_derivatives_match_finite_differences() {
    let rotor = presets::paper_rotor();
    let candidates = eigenfit_rotor::effects::candidates(&rotor);
    for kind in
        ["section-change", "point-mass", "shaft-rotary-inertia", "timoshenko-shaft", "shaft-stiffness-loss"]
    {
        for c in candidates.iter().filter(|c| c.kind == kind).take(3) {
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
