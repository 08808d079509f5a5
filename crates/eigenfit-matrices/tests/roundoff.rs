//! The round-off refusal threshold checked on a model it was not calibrated on (issue 13): the
//! plate from Matrix Market files, against scipy's ARPACK frequencies (an independent solver).
//! The estimate must bound the actual error and stay far below the refusal threshold.

use eigenfit_core::eigen::roundoff::{relative_roundoff, trial_vector_roundoff, MAX_RELATIVE_ROUNDOFF};
use eigenfit_core::eigen::{EigenSolver, SparseSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_matrices::MatricesModel;
use serde_json::Value;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/plate").join(name)
}

#[test]
fn the_plate_is_accepted_and_its_roundoff_estimate_bounds_the_error() {
    let model = MatricesModel::from_toml_file(&data("model.toml")).unwrap();
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(data("scipy_reference.json")).unwrap()).unwrap();
    let system = model.assemble(&model.parameters().nominal_values()).unwrap();
    let modes = SparseSolver::default().lowest(&system, 3).unwrap();
    let levels = relative_roundoff(&system, &modes);
    for (j, f) in modes.frequencies_hz().iter().enumerate() {
        let scipy = reference["frequencies_hz"][j].as_f64().unwrap();
        // λ ∝ f², so the eigenvalue's relative error is about twice the frequency's.
        let error = 2.0 * ((f - scipy) / scipy).abs();
        println!("plate mode {}: estimate {:.1e}, error against scipy {error:.1e}", j + 1, levels[j]);
        assert!(levels[j] < 1e-6 * MAX_RELATIVE_ROUNDOFF, "mode {}: {:e}", j + 1, levels[j]);
        assert!(error <= levels[j] + 1e-9, "mode {}: error {error:e} > estimate {:e}", j + 1, levels[j]);
    }
    // The solver-failure fallback agrees that nothing here is near the threshold.
    let trial = trial_vector_roundoff(&system);
    println!("plate trial-vector estimate {trial:.1e}");
    assert!(trial < 1e-3 * MAX_RELATIVE_ROUNDOFF, "{trial:e}");
}
