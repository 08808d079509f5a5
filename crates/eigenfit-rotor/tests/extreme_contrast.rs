//! Regression from fuzzing (`fuzz/fuzz_targets/model_to_modes.rs`): a rotor whose supports differ
//! by 13 decades (6.4e14 and 51 N/m), with micro point masses. Lanczos "converged" (Paige's
//! estimate) to Ritz pairs whose refined eigenvalues came out of order, or (10 modes) 1 % off the
//! dense solver's. The banded solver now checks the true residual of such pairs and the order,
//! and falls back (here to the dense solver) rather than return them.

use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit_rotor::Rotor;

const MODEL: &str = include_str!("fixtures/models/extreme_contrast.toml");

#[test]
fn banded_solver_never_returns_modes_out_of_order() {
    let rotor = Rotor::from_toml_str(MODEL).expect("a valid model");
    let system = rotor.nominal_system().expect("assembles");
    let dense = DenseSolver.lowest(&system, 21).expect("dense solves it");
    for count in [3, 10, 21] {
        let banded = BandedSolver::default().lowest(&system, count).expect("banded solves it");
        let l = banded.eigenvalues.as_slice();
        assert!(l.windows(2).all(|w| w[0] <= w[1]), "count {count}: not ascending {l:?}");
        for (k, (a, b)) in l.iter().zip(dense.eigenvalues.iter()).enumerate().skip(1) {
            assert!((a / b - 1.0).abs() < 1e-9, "count {count}, λ{k}: {a} vs dense {b}");
        }
    }
}
