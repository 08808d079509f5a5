//! The committed 920-DOF stiffened plate (scripts/plate_matrices.py) against scipy's answers
//! (scipy_reference.json, measured.csv: ARPACK shift-invert, an independent solver) and
//! against eigenfit's own dense solver and finite differences.

use eigenfit_core::eigen::{DenseSolver, EigenSolver, SparseSolver};
use eigenfit_core::model::{finite_difference_derivative, StructuralModel};
use eigenfit_core::sensitivity::Sensitivities;
use eigenfit_matrices::MatricesModel;
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/plate").join(name)
}

fn plate() -> MatricesModel {
    MatricesModel::from_toml_file(&data("model.toml")).unwrap()
}

fn reference() -> Value {
    serde_json::from_str(&std::fs::read_to_string(data("scipy_reference.json")).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn nominal_frequencies_and_sensitivities_match_scipy() {
    let model = plate();
    assert_eq!(model.dofs(), 920);
    // The DOF map as dofs.csv gives it: edge nodes have no w (simply supported).
    let map = model.dof_map().unwrap();
    assert_eq!(map.len(), 920);
    assert_eq!((map[0].node, map[0].direction.as_str()), (1, "rx"));
    assert!(map.iter().any(|d| d.direction == "z" && d.x > 0.0 && d.y > 0.0));
    let reference = reference();
    let expected = floats(&reference["frequencies_hz"]);
    let p = model.parameters().nominal_values();
    let s = Sensitivities::compute(&model, &SparseSolver::default(), &p, expected.len()).unwrap();
    let f = s.modes.frequencies_hz();
    for (k, (a, b)) in f.iter().zip(&expected).enumerate() {
        assert!((a / b - 1.0).abs() < 1e-9, "mode {}: eigenfit {a} Hz, scipy {b} Hz", k + 1);
    }
    for (i, name) in ["zone1", "zone2", "zone3", "zone4"].iter().enumerate() {
        let expected = floats(&reference["sensitivities_hz"][name]);
        for (k, b) in expected.iter().enumerate() {
            let a = s.frequencies_hz[(k, i)];
            assert!((a - b).abs() < 1e-7 * b.abs().max(1e-3 * f[k]), "df{}/d{name}: {a} vs scipy {b}", k + 1);
        }
    }
}

#[test]
fn sparse_and_dense_solvers_agree_and_no_mode_is_missed() {
    let model = plate();
    let system = model.assemble(&[1.25, 0.8, 1.1, 0.9]).unwrap();
    let (sparse, next) = SparseSolver::default().lowest_with_next(&system, 12).unwrap();
    let dense = DenseSolver.lowest(&system, 13).unwrap();
    for k in 0..12 {
        assert!((sparse.eigenvalues[k] / dense.eigenvalues[k] - 1.0).abs() < 1e-10, "mode {k}");
    }
    assert!(next > sparse.eigenvalues[11] && next <= dense.eigenvalues[12]);
}

#[test]
fn derivatives_are_the_zone_matrices_exactly() {
    let model = plate();
    let p = [1.3, 0.7, 1.0, 2.0];
    for i in 0..4 {
        let exact = model.derivative(&p, i).unwrap();
        let fd = finite_difference_derivative(&model, &p, i).unwrap();
        let (a, b) = (exact.stiffness.to_dense(), fd.stiffness.to_dense());
        assert!((&a - &b).amax() < 1e-6 * a.amax(), "zone{}", i + 1);
        assert!(exact.mass.is_empty());
    }
}

#[test]
fn scipy_measured_frequencies_are_reproduced_at_the_true_zone_factors() {
    let model = plate();
    let measured: Vec<f64> = std::fs::read_to_string(data("measured.csv"))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("mode"))
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let truth: Value = serde_json::from_str(&std::fs::read_to_string(data("truth.json")).unwrap()).unwrap();
    let p: Vec<f64> = (1..=4).map(|i| truth["parameters"][format!("zone{i}")].as_f64().unwrap()).collect();
    let system = model.assemble(&p).unwrap();
    let f = SparseSolver::default().lowest(&system, measured.len()).unwrap().frequencies_hz();
    for (a, b) in f.iter().zip(&measured) {
        assert!((a / b - 1.0).abs() < 1e-9, "{a} vs scipy {b}");
    }
}
