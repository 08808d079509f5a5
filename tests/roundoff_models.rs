//! The round-off refusal threshold (calibrated on the uniform rotor) checked on other rotors
//! (issue 13): the paper rotor on ever finer meshes, whose converged frequency is known from a
//! moderate mesh, and an extreme-contrast rotor. Wherever a frequency is accepted (estimate ≤
//! MAX_RELATIVE_ROUNDOFF) the estimate bounds the actual eigenvalue error, so an accepted
//! answer is never noise; run with `--nocapture` for the table quoted in docs/user-guide.md.

use eigenfit::core::eigen::roundoff::{relative_roundoff, MAX_RELATIVE_ROUNDOFF};
use eigenfit::core::eigen::{BandedSolver, DenseSolver, EigenSolver};
use eigenfit::core::model::StructuralModel;
use eigenfit::rotor::{mesh, presets};

fn lowest(model: &dyn StructuralModel, solver: &dyn EigenSolver) -> Option<(f64, f64)> {
    let system = model.assemble(&model.parameters().nominal_values()).ok()?;
    let modes = solver.lowest(&system, 1).ok()?;
    Some((modes.eigenvalues[0], relative_roundoff(&system, &modes)[0]))
}

#[test]
fn accepted_fine_meshes_of_the_paper_rotor_are_within_their_estimate() {
    let base = presets::paper_rotor();
    // Cubic Hermite elements converge as h⁴: at factor 16 the discretisation error is far
    // below anything compared here.
    let (reference, _) = lowest(&mesh::refined(&base, 16).unwrap(), &BandedSolver::default()).unwrap();
    for factor in [64, 256, 512, 1024] {
        let model = mesh::refined(&base, factor).unwrap();
        let Some((lambda, estimate)) = lowest(&model, &BandedSolver::default()) else {
            println!("paper rotor ×{factor} ({} DOF): solver failed", model.dofs());
            continue;
        };
        let error = ((lambda - reference) / reference).abs();
        println!("paper rotor ×{factor} ({} DOF): estimate {estimate:.1e}, error {error:.1e}", model.dofs());
        if estimate <= MAX_RELATIVE_ROUNDOFF {
            assert!(error <= estimate + 1e-9, "×{factor}: error {error:e} > estimate {estimate:e}");
        }
    }
}

#[test]
fn an_extreme_contrast_rotor_is_within_its_estimate_or_refused() {
    // The paper rotor with supports 10¹⁰ times stiffer than its softest: banded against dense.
    let base = presets::paper_rotor();
    for k in [1e9, 1e12, 1e15] {
        let p = vec![k, 1e5];
        let system = base.assemble(&p).unwrap();
        let dense = DenseSolver.lowest(&system, 1).unwrap();
        let banded = BandedSolver::default().lowest(&system, 1).unwrap();
        let estimate = relative_roundoff(&system, &banded)[0];
        let gap = ((banded.eigenvalues[0] - dense.eigenvalues[0]) / dense.eigenvalues[0]).abs();
        println!("paper rotor k_K1 = {k:e}: estimate {estimate:.1e}, banded vs dense {gap:.1e}");
        if estimate <= MAX_RELATIVE_ROUNDOFF {
            // Both solvers are backward stable: each within the estimate of the exact value.
            assert!(gap <= 2.0 * estimate + 1e-12, "k = {k:e}: {gap:e} > 2 × {estimate:e}");
        }
    }
}
