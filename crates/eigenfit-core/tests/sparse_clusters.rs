//! The sparse solver on clustered spectra (issue 28): an eigenvalue of multiplicity far above the
//! modes asked for is answered without chasing its copies, and a spectrum spread far above zero
//! (too tight for Lanczos inverted at zero) is answered through a shift just below it. Sizes above the dense solver's limit, so
//! the sparse path answers alone.

use eigenfit_core::eigen::{EigenSolver, SparseSolver, DENSE_MAX_DOFS};
use eigenfit_core::matrix::{CscSymmetric, System};

const N: usize = DENSE_MAX_DOFS + 500;

fn diagonal_system(k: impl Fn(usize) -> f64) -> System {
    let kk = CscSymmetric::from_triplets(N, (0..N).map(|i| (i, i, k(i))));
    let m = CscSymmetric::from_triplets(N, (0..N).map(|i| (i, i, 1.0)));
    System::sparse(kk, m).unwrap()
}

/// ΦᵀMΦ = I for M = I: the returned shapes are an orthonormal basis of the eigenspace.
fn assert_orthonormal(shapes: &eigenfit_core::nalgebra::DMatrix<f64>) {
    let gram = shapes.transpose() * shapes;
    for i in 0..gram.nrows() {
        for j in 0..gram.ncols() {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((gram[(i, j)] - want).abs() < 1e-10, "ΦᵀMΦ[{i},{j}] = {}", gram[(i, j)]);
        }
    }
}

#[test]
fn an_eigenvalue_of_multiplicity_n_is_answered_without_chasing_its_copies() {
    let system = diagonal_system(|_| 1000.0);
    let (modes, next) = SparseSolver::default().lowest_with_next(&system, 3).unwrap();
    for &lambda in modes.eigenvalues.iter() {
        assert!((lambda / 1000.0 - 1.0).abs() < 1e-12, "{lambda}");
    }
    // The next eigenvalue is another copy: the certificate says so, it is no gap.
    assert!((next / 1000.0 - 1.0).abs() < 1e-6, "next {next}");
    assert_orthonormal(&modes.shapes);
}

#[test]
fn distinct_modes_below_a_large_cluster_are_all_found() {
    // λ = 1, 2, then 5 repeated N − 2 times: the lowest three are 1, 2, 5.
    let system = diagonal_system(|i| [1.0, 2.0].get(i).copied().unwrap_or(5.0));
    let (modes, next) = SparseSolver::default().lowest_with_next(&system, 3).unwrap();
    let want = [1.0, 2.0, 5.0];
    for (&lambda, w) in modes.eigenvalues.iter().zip(want) {
        assert!((lambda / w - 1.0).abs() < 1e-12, "{lambda} vs {w}");
    }
    assert!((next / 5.0 - 1.0).abs() < 1e-6, "next {next}");
    assert_orthonormal(&modes.shapes);
}

#[test]
fn a_spectrum_spread_far_above_zero_is_answered_through_a_shift_below_it() {
    // λᵢ = 1001 + i: 0.1 % apart inverted at zero, where shift-invert Lanczos runs out of steps;
    // shifted to just below λ₁ the inverted gaps are of order one.
    let system = diagonal_system(|i| 1001.0 + i as f64);
    let (modes, next) = SparseSolver::default().lowest_with_next(&system, 3).unwrap();
    for (j, &lambda) in modes.eigenvalues.iter().enumerate() {
        let want = 1001.0 + j as f64;
        assert!((lambda / want - 1.0).abs() < 1e-10, "mode {j}: {lambda} vs {want}");
    }
    // The certificate: nothing between the third and the bound, which lies below the fourth.
    assert!(next > 1003.0 && next <= 1004.0, "next {next}");
    assert_orthonormal(&modes.shapes);
}
