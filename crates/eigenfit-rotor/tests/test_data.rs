//! Real test data on the planar rotor: UFF round trip, a pyuff-written export of an independent
//! finite-element model, and the mirror ambiguity of a symmetric rotor resolved by shapes.

use eigenfit_core::analysis::{uncertainty, ShapeFit};
use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::measurement::{sensors, uff, Measurement};
use eigenfit_core::problem::{Objective, Pairing, Problem};
use eigenfit_core::update::{Driver, LevenbergMarquardt, UpdateStrategy};
use eigenfit_rotor::Rotor;
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/uff").join(name)
}

fn symmetric() -> Rotor {
    Rotor::from_toml_file(data("symmetric_rotor.toml")).unwrap()
}

fn fixture() -> (uff::UffFile, Value) {
    let file = uff::parse(&std::fs::read_to_string(data("symmetric_rotor.unv")).unwrap()).unwrap();
    let json = serde_json::from_str(&std::fs::read_to_string(data("symmetric_rotor.json")).unwrap()).unwrap();
    (file, json)
}

const TRUTH: [f64; 2] = [2.5e5, 0.8e5];

#[test]
fn written_modes_map_back_onto_the_model_dofs() {
    let rotor = symmetric();
    let modes = DenseSolver.lowest(&rotor.nominal_system().unwrap(), 4).unwrap();
    let (nodes, mut uff_modes) = rotor.uff_modes(&modes);
    // A horizontal-plane mode (x only), as a 3-D model would export beside the vertical ones.
    let mut horizontal = uff_modes[0].clone();
    horizontal.number = 5;
    horizontal.values.iter_mut().for_each(|(_, v)| *v = vec![v[1], 0.0, 0.0, 0.0, v[3], 0.0]);
    uff_modes.push(horizontal);
    let file = uff::parse(&uff::write("round trip", &nodes, &uff_modes)).unwrap();
    let set = sensors::map_by_coordinates(&file, &rotor, 1e-6).unwrap();
    let (measurement, notes) = sensors::measurement(&file, &set).unwrap();
    assert_eq!(notes.len(), 1);
    assert!(
        notes[0].starts_with("mode 5 (")
            && notes[0].ends_with("moves only in directions the model does not have: left out")
    );
    assert_eq!(
        set.ignored,
        ["x at node(s) 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11", "ry at node(s) 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11"]
    );
    assert_eq!(measurement.len(), 4);
    // Every node's y and rx are sensors (x, z, ry, rz are zero: not measured).
    assert_eq!(set.sensors.len(), 2 * rotor.nodes().len());
    for (k, m) in measurement.modes().iter().enumerate() {
        assert!((m.frequency_hz / modes.frequencies_hz()[k] - 1.0).abs() < 5e-6);
        let big = modes.shape(k).iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        for (s, v) in set.sensors.iter().zip(m.shape.as_ref().unwrap()) {
            // E13.5 keeps 6 significant digits; zero model entries come back as exact zeros.
            assert!((v - modes.shapes[(s.dof, k)]).abs() <= 5e-6 * big, "{}: {v}", s.name());
        }
    }
}

#[test]
fn the_independent_model_agrees_and_sensors_map_by_coordinates() {
    let (file, json) = fixture();
    let rotor = symmetric();
    // numpy's Hermite-element model of the same rotor (generate.py) against ours.
    let ours = DenseSolver.lowest(&rotor.system_at(&TRUTH).unwrap(), 3).unwrap().frequencies_hz();
    for (a, b) in ours.iter().zip(json["noise_free_frequencies_hz"].as_array().unwrap()) {
        let b = b.as_f64().unwrap();
        assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
    }
    let set = sensors::map_by_coordinates(&file, &rotor, 1e-3).unwrap();
    let names: Vec<String> = set.sensors.iter().map(|s| s.name()).collect();
    assert_eq!(names, ["node 101 y", "node 102 y", "node 103 y", "node 104 y", "node 105 y"]);
    assert_eq!(set.sensors.iter().map(|s| s.model_node).collect::<Vec<_>>(), [0, 2, 5, 8, 10]);
    assert_eq!(set.ignored, ["x at node(s) 101, 102, 103, 104, 105"]);

    // A sensor off the axis (on the shaft's surface) still ties to its axial node.
    let mut surface = file.clone();
    surface.nodes[1].coordinates[0] = 0.007;
    surface.nodes[1].coordinates[1] = -0.05;
    let on_surface = sensors::map_by_coordinates(&surface, &rotor, 1e-3).unwrap();
    assert_eq!(on_surface.sensors, set.sensors);

    // A node off the model names itself and its nearest model node.
    let mut moved = file.clone();
    moved.nodes[2].coordinates[2] += 0.01;
    let e = sensors::map_by_coordinates(&moved, &rotor, 1e-3).unwrap_err().to_string();
    assert!(
        e.contains("node 103 at (0, 0, 0.26") && e.contains("nearest model node 5 is 0.0100 m away"),
        "{e}"
    );
}

/// Frequencies alone cannot tell the bearings apart: a frequency-only fit and its mirror
/// (bearings swapped) fit equally well, so which one a run returns is an accident of its path.
/// With shapes the mirror misfits and the truth is found from the mirror side.
#[test]
fn frequencies_alone_admit_the_mirror_solution_and_shapes_exclude_it() {
    let (file, _) = fixture();
    let rotor = symmetric();
    let set = sensors::map_by_coordinates(&file, &rotor, 1e-3).unwrap();
    let (measured, notes) = sensors::measurement(&file, &set).unwrap();
    assert!(notes.is_empty());
    let start = [0.9e5, 2.0e5];

    let without_shapes = measured
        .modes()
        .iter()
        .map(|m| eigenfit_core::measurement::MeasuredMode { shape: None, ..m.clone() })
        .collect();
    let freq_only = Problem::new(&rotor, DenseSolver, Measurement::new(without_shapes).unwrap());
    let est = Driver::default().run(&freq_only, &mut LevenbergMarquardt::default(), &start).unwrap();
    let p = &est.parameters;
    let swapped = [p[1], p[0]];
    let (c1, c2) = (freq_only.cost(p).unwrap(), freq_only.cost(&swapped).unwrap());
    assert!((c1 - c2).abs() <= 1e-9 * c1.max(1e-20), "{c1} vs {c2}");
    assert!((p[0] / p[1] - 1.0).abs() > 0.5, "the two solutions are distinct: {p:?}");

    let fit = ShapeFit::new(
        Problem::new(&rotor, DenseSolver, measured).with_pairing(Pairing::Mac { sensor_dofs: set.dofs() }),
        0.05,
    );
    let mut damped = LevenbergMarquardt::default();
    let est = Driver::default().run(&fit, &mut damped as &mut dyn UpdateStrategy, &start).unwrap();
    assert!(est.termination.is_converged(), "{}", est.termination);
    // No measured shape std: the default weights are not σ, so the intervals come from the
    // residual scatter (`ShapeFit::uncertainty`), not from the weights.
    assert!(!est.last.has_std);
    assert!(uncertainty(&fit, &est.last).is_none());
    let mut fit = fit;
    let (u, _sigma_hat) = fit.uncertainty(&est.last).unwrap();
    for (i, name) in ["drive_end", "free_end"].iter().enumerate() {
        let [lo, hi] = u.intervals[i];
        assert!(lo <= TRUTH[i] && TRUTH[i] <= hi, "{name}: truth {} outside [{lo}, {hi}]", TRUTH[i]);
        let mirror = TRUTH[1 - i];
        assert!(!(lo <= mirror && mirror <= hi), "{name}: mirror {mirror} inside [{lo}, {hi}]");
    }
    assert_eq!(est.last.paired_modes, [0, 1, 2]);
    // The shapes make the mirror a much worse fit than the estimate.
    let mirror = [est.parameters[1], est.parameters[0]];
    let (at, at_mirror) =
        (Objective::cost(&fit, &est.parameters).unwrap(), Objective::cost(&fit, &mirror).unwrap());
    assert!(at_mirror > 100.0 * at, "{at} vs mirror {at_mirror}");
    // The cost skips the shapes' derivatives, not any row: it is the linearisation's.
    for p in [&est.parameters[..], &mirror[..], &start[..]] {
        let (cost, lin) = (Objective::cost(&fit, p).unwrap(), fit.linearise(p).unwrap());
        assert!((cost / lin.cost() - 1.0).abs() < 1e-12, "{p:?}: {cost} vs {}", lin.cost());
    }
}

/// One sensor gives every MAC = 1 (to round-off): the mode nearest in frequency is taken.
#[test]
fn equal_macs_pair_with_the_lowest_mode() {
    let rotor = symmetric();
    let p = rotor.nominal_stiffnesses();
    let modes = DenseSolver.lowest(&rotor.nominal_system().unwrap(), 3).unwrap();
    let f = modes.frequencies_hz();
    let dof = Rotor::displacement_dof(2);
    let measured = Measurement::new(
        (0..3)
            .map(|k| eigenfit_core::measurement::MeasuredMode {
                mode: k,
                frequency_hz: f[k],
                std_hz: None,
                shape: Some(vec![modes.shapes[(dof, k)]]),
            })
            .collect(),
    )
    .unwrap();
    let problem =
        Problem::new(&rotor, DenseSolver, measured).with_pairing(Pairing::Mac { sensor_dofs: vec![dof] });
    assert_eq!(problem.linearise(&p).unwrap().paired_modes, [0, 1, 2]);
}
