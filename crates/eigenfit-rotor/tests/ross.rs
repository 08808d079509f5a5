//! Cross-check against ROSS (petrobras/ross) for the paper's rotor geometry, and the example file.

use eigenfit_core::eigen::{DenseSolver, EigenSolver};
use eigenfit_core::model::StructuralModel;
use eigenfit_rotor::Rotor;

/// 10 equal elements, Ø14 mm × 500 mm steel shaft, point disks 0.4 kg at node 2 and 1.35 kg at
/// node 8, 1e5 N/m supports at nodes 0 and 10: the `ross-example` preset.
fn ross_rotor() -> Rotor {
    eigenfit_rotor::presets::ross_example()
}

/// ROSS's undamped natural frequencies (Hz) as printed, with half a unit of the last printed digit.
const ROSS: [(f64, f64); 3] = [(36.954, 5e-4), (81.302, 5e-4), (302.94, 5e-3)];

fn assert_ross(rotor: &Rotor) {
    let modes = DenseSolver.lowest(&rotor.nominal_system().unwrap(), 3).unwrap();
    let f = modes.frequencies_hz();
    for (k, (fi, (r, half))) in f.iter().zip(ROSS).enumerate() {
        assert!((fi - r).abs() <= half, "mode {k}: {fi} Hz vs ROSS {r} Hz (allowed ±{half})");
    }
}

#[test]
fn reproduces_ross_frequencies() {
    // We get 36.9538033, 81.3024951, 302.9397445 Hz.
    assert_ross(&ross_rotor());
}

#[test]
fn example_file_is_the_ross_rotor() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/rotor.toml");
    let rotor = Rotor::from_toml_file(path).unwrap();
    assert_ross(&rotor);
    let names: Vec<_> = rotor.parameters().iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["k_drive_end", "k_free_end"]);
    // Same matrices as the builder's uniform mesh, up to the rounding of the node positions.
    let a = rotor.nominal_system().unwrap();
    let b = ross_rotor().nominal_system().unwrap();
    assert!((a.stiffness() - b.stiffness()).amax() < 1e-9 * b.stiffness().amax());
    assert!((a.mass() - b.mass()).amax() < 1e-12 * b.mass().amax());
}
