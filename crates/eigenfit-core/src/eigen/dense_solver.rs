//! The default, pure-nalgebra eigen-solver: Cholesky reduction to a standard symmetric problem.

use crate::eigen::{
    apply_sign_rule, check_count, shifted_twice, with_next_by_one_more_mode, EigenSolver, ModeRequest, Modes,
    SolveError, SolvedModes,
};
use crate::matrix::System;
use nalgebra::{Cholesky, DMatrix, DVector, SymmetricEigen};

/// Largest model (DOFs) handed to a dense solver — the CLI's `dense`/`lapack` choice and the
/// fallbacks of the banded and sparse solvers: its two n×n matrices take 16n² bytes (256 MB
/// here) and its solve O(n³) time. 4002 admits the 2000-element uniform rotor.
pub const DENSE_MAX_DOFS: usize = 4002;

/// Dense solver for the lowest modes, accurate to round-off *relative to each eigenvalue*
/// when at most half the modes are requested.
///
/// The textbook reduction M = LLᵀ, A = L⁻¹KL⁻ᵀ loses the lowest eigenvalues to round-off of
/// size ε·λ_max: for a stiff shaft on soft supports (λ_max/λ₁ ≈ 10⁸) that is 10⁻⁸ relative.
/// This solver reduces the inverted problem instead: with K_σ = K + σM = LLᵀ (σ = 0 when K is
/// positive definite, a small shift for rigid-body modes), B = L⁻¹ML⁻ᵀ has eigenvalues
/// μ = 1/(λ + σ), the lowest modes become the largest μ, and their relative accuracy is
/// ε·λ/λ₁. Φ = L⁻ᵀY/√μ is mass-normalised. When more than half the modes are requested the
/// textbook reduction is used instead, which keeps the whole basis M-orthonormal to ε·λ_max.
/// Needs no system library; O(n³).
#[derive(Debug, Clone, Copy, Default)]
pub struct DenseSolver;

impl EigenSolver for DenseSolver {
    fn name(&self) -> &'static str {
        "dense"
    }

    /// Its certificate is the next eigenvalue itself, from a solve of one mode more.
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError> {
        with_next_by_one_more_mode(system, request, |count, vectors| {
            if vectors {
                self.modes(system, count)
            } else {
                let eigenvalues = self.eigenvalues_only(system, count)?;
                Ok(Modes { eigenvalues, shapes: DMatrix::zeros(system.dofs(), 0) })
            }
        })
        .map_err(|e| e.located(system))
    }
}

impl DenseSolver {
    /// The lowest `count` modes with their shapes.
    fn modes(&self, system: &System, count: usize) -> Result<Modes, SolveError> {
        check_count(system, count)?;
        let (k, m) = (system.stiffness(), system.mass());
        // M must be positive definite for the problem to be symmetric-definite at all.
        if Cholesky::new(m.clone()).is_none() {
            return Err(SolveError::MassNotPositiveDefinite { detail: None, dof: None });
        }
        if 2 * count > system.dofs() {
            return mass_reduction(k, m, count);
        }
        if let Some(chol) = Cholesky::new(k.clone()).filter(well_conditioned) {
            return inverted_solve(&chol, m, 0.0, count);
        }
        // Rigid-body modes: K is singular.
        let scale = k.diagonal().amax() / m.diagonal().amax();
        shifted_twice(scale, |sigma| shifted(k, m, sigma, count))
    }

    /// Eigenvalues only: the same arithmetic as `modes` on its common path
    /// (K positive definite, at most half the modes), without accumulating eigenvectors.
    fn eigenvalues_only(&self, system: &System, count: usize) -> Result<DVector<f64>, SolveError> {
        check_count(system, count)?;
        let (k, m) = (system.stiffness(), system.mass());
        if Cholesky::new(m.clone()).is_none() {
            return Err(SolveError::MassNotPositiveDefinite { detail: None, dof: None });
        }
        if 2 * count <= system.dofs() {
            if let Some(chol) = Cholesky::new(k.clone()).filter(well_conditioned) {
                let b = reduced_inverted(&chol, m)?;
                let mut mu = b.symmetric_eigenvalues().as_slice().to_vec();
                mu.sort_by(|a, b| b.total_cmp(a));
                mu.truncate(count);
                if mu.iter().any(|&v| v <= 0.0) {
                    return Err(SolveError::Backend {
                        backend: "dense",
                        detail: "a reduced eigenvalue is not positive".into(),
                    });
                }
                let eigenvalues = DVector::from_iterator(count, mu.iter().map(|&v| 1.0 / v));
                if eigenvalues.iter().any(|v| !v.is_finite()) {
                    return Err(SolveError::Backend { backend: "dense", detail: "non-finite result".into() });
                }
                return Ok(eigenvalues);
            }
        }
        // Rigid-body modes or most of the spectrum: the full solve.
        self.modes(system, count).map(|modes| modes.eigenvalues)
    }
}

/// B = L⁻¹ M L⁻ᵀ, symmetrised, for K + σM = LLᵀ.
fn reduced_inverted(
    chol: &Cholesky<f64, nalgebra::Dyn>,
    m: &DMatrix<f64>,
) -> Result<DMatrix<f64>, SolveError> {
    let l = chol.l();
    let x = l.solve_lower_triangular(m).ok_or_else(|| not_pd("zero pivot in L"))?;
    let b = l.solve_lower_triangular(&x.transpose()).ok_or_else(|| not_pd("zero pivot in L"))?;
    Ok((&b + b.transpose()) * 0.5)
}

/// A Cholesky factor whose pivots do not reveal a (numerically) singular matrix.
fn well_conditioned(c: &Cholesky<f64, nalgebra::Dyn>) -> bool {
    let d = c.l_dirty().diagonal();
    let (dmin, dmax) = d.iter().fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v.abs()), b.max(v.abs())));
    dmin > 1e-7 * dmax
}

fn shifted(k: &DMatrix<f64>, m: &DMatrix<f64>, sigma: f64, count: usize) -> Result<Modes, SolveError> {
    let chol = Cholesky::new(k + m * sigma).ok_or(SolveError::Backend {
        backend: "dense",
        detail: "K + σM is not positive definite: K has negative stiffness".into(),
    })?;
    inverted_solve(&chol, m, sigma, count)
}

/// Lowest `count` modes from K + σM = LLᵀ: eigen-decompose B = L⁻¹ML⁻ᵀ, μ = 1/(λ + σ).
fn inverted_solve(
    chol: &Cholesky<f64, nalgebra::Dyn>,
    m: &DMatrix<f64>,
    sigma: f64,
    count: usize,
) -> Result<Modes, SolveError> {
    let l = chol.l();
    // Largest μ first = lowest λ first.
    let (eig, order) = lowest_pairs(reduced_inverted(chol, m)?, count, |mu| -mu)?;
    if order.iter().any(|&i| eig.eigenvalues[i] <= 0.0) {
        return Err(SolveError::Backend {
            backend: "dense",
            detail: "a reduced eigenvalue is not positive".into(),
        });
    }
    let eigenvalues = DVector::from_iterator(count, order.iter().map(|&i| 1.0 / eig.eigenvalues[i] - sigma));
    let y = DMatrix::from_columns(
        &order.iter().map(|&i| eig.eigenvectors.column(i) / eig.eigenvalues[i].sqrt()).collect::<Vec<_>>(),
    );
    let shapes = l.transpose().solve_upper_triangular(&y).ok_or_else(|| not_pd("zero pivot in Lᵀ"))?;
    finish(eigenvalues, shapes)
}

/// All or most modes: the textbook reduction M = LLᵀ, A = L⁻¹KL⁻ᵀ, accurate to ε·λ_max in
/// absolute terms for every mode, so the whole basis stays M-orthonormal (modal expansions).
fn mass_reduction(k: &DMatrix<f64>, m: &DMatrix<f64>, count: usize) -> Result<Modes, SolveError> {
    let chol =
        Cholesky::new(m.clone()).ok_or(SolveError::MassNotPositiveDefinite { detail: None, dof: None })?;
    let l = chol.l();
    let x = l.solve_lower_triangular(k).ok_or_else(|| not_pd("zero pivot in L"))?;
    let a = l.solve_lower_triangular(&x.transpose()).ok_or_else(|| not_pd("zero pivot in L"))?;
    let (eig, order) = lowest_pairs((&a + a.transpose()) * 0.5, count, |lambda| lambda)?;
    let eigenvalues = DVector::from_iterator(count, order.iter().map(|&i| eig.eigenvalues[i]));
    let y = DMatrix::from_columns(&order.iter().map(|&i| eig.eigenvectors.column(i)).collect::<Vec<_>>());
    let shapes = l.transpose().solve_upper_triangular(&y).ok_or_else(|| not_pd("zero pivot in Lᵀ"))?;
    finish(eigenvalues, shapes)
}

/// The eigen-decomposition of the symmetric `a` and the indices of its `count` eigenpairs with
/// the lowest `key(eigenvalue)`, in that order.
fn lowest_pairs(
    a: DMatrix<f64>,
    count: usize,
    key: impl Fn(f64) -> f64,
) -> Result<(SymmetricEigen<f64, nalgebra::Dyn>, Vec<usize>), SolveError> {
    let eig = SymmetricEigen::try_new(a, f64::EPSILON, 0).ok_or(SolveError::Backend {
        backend: "dense",
        detail: "symmetric QR iteration did not converge".into(),
    })?;
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| key(eig.eigenvalues[i]).total_cmp(&key(eig.eigenvalues[j])));
    order.truncate(count);
    Ok((eig, order))
}

/// Rejects non-finite results and applies the sign rule.
fn finish(eigenvalues: DVector<f64>, mut shapes: DMatrix<f64>) -> Result<Modes, SolveError> {
    if eigenvalues.iter().chain(shapes.iter()).any(|v| !v.is_finite()) {
        return Err(SolveError::Backend { backend: "dense", detail: "non-finite result".into() });
    }
    apply_sign_rule(&mut shapes);
    Ok(Modes { eigenvalues, shapes })
}

fn not_pd(detail: &str) -> SolveError {
    SolveError::MassNotPositiveDefinite { detail: Some(detail.into()), dof: None }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_dof_chain_matches_closed_form_and_identities() {
        // m = diag(1, 2), springs 3 (ground–1) and 1 (1–2).
        let k = DMatrix::from_row_slice(2, 2, &[4.0, -1.0, -1.0, 1.0]);
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 2.0]);
        let sys = System::new(k.clone(), m.clone()).unwrap();
        let modes = DenseSolver.lowest(&sys, 2).unwrap();
        // det(K − λM) = 2λ² − 9λ + 3 = 0
        let disc = (81.0_f64 - 24.0).sqrt();
        assert!((modes.eigenvalues[0] - (9.0 - disc) / 4.0).abs() < 1e-13);
        assert!((modes.eigenvalues[1] - (9.0 + disc) / 4.0).abs() < 1e-13);
        let phi = &modes.shapes;
        assert!((phi.transpose() * &m * phi - DMatrix::identity(2, 2)).abs().max() < 1e-13);
        let lam = DMatrix::from_diagonal(&modes.eigenvalues);
        assert!((phi.transpose() * &k * phi - lam).abs().max() < 1e-12);
    }

    #[test]
    fn rejects_indefinite_mass_and_bad_counts() {
        let sys = System::new(DMatrix::identity(2, 2), DMatrix::from_diagonal_element(2, 2, -1.0)).unwrap();
        assert!(matches!(DenseSolver.lowest(&sys, 1), Err(SolveError::MassNotPositiveDefinite { .. })));
        let sys = System::new(DMatrix::identity(2, 2), DMatrix::identity(2, 2)).unwrap();
        assert_eq!(DenseSolver.lowest(&sys, 3), Err(SolveError::TooManyModes { requested: 3, available: 2 }));
        assert_eq!(DenseSolver.lowest(&sys, 0), Err(SolveError::NoModes));
    }

    #[test]
    fn eigenvalues_only_match_the_full_solve() {
        let n = 30;
        let k = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 2.0 + 1e-6 * (i == 0) as u8 as f64,
            1 => -1.0,
            _ => 0.0,
        });
        let m = DMatrix::from_fn(n, n, |i, j| if i == j { 1.0 + 0.1 * (i % 3) as f64 } else { 0.0 });
        let sys = System::new(k.clone(), m).unwrap();
        for count in [1, 3, 15, 20] {
            let full = DenseSolver.lowest(&sys, count).unwrap().eigenvalues;
            let only = DenseSolver.lowest_eigenvalues(&sys, count).unwrap();
            assert!((&full - &only).amax() <= 1e-15 * full.amax(), "{full} vs {only}");
        }
        let softer = System::new(k.map(|v| if v == 2.0 + 1e-6 { 1.0 } else { v }), DMatrix::identity(n, n));
        let softer = softer.unwrap();
        assert_eq!(
            DenseSolver.lowest_eigenvalues(&softer, 2),
            DenseSolver.lowest(&softer, 2).map(|m| m.eigenvalues)
        );
    }

    #[test]
    fn free_free_rigid_body_modes_are_solved() {
        // Two unit masses joined by a unit spring, no ground: λ = 0 and 2.
        let k = DMatrix::from_row_slice(2, 2, &[1.0, -1.0, -1.0, 1.0]);
        let sys = System::new(k, DMatrix::identity(2, 2)).unwrap();
        let modes = DenseSolver.lowest(&sys, 2).unwrap();
        assert!(modes.eigenvalues[0].abs() < 1e-14);
        assert!((modes.eigenvalues[1] - 2.0).abs() < 1e-14);
    }

    #[test]
    fn a_request_gets_what_it_asks_for() {
        // Two unit masses, springs 1 (ground–1) and 1 (1–2): λ = (3 ∓ √5)/2.
        let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 1.0]);
        let sys = System::new(k, DMatrix::identity(2, 2)).unwrap();
        let (low, high) = ((3.0 - 5f64.sqrt()) / 2.0, (3.0 + 5f64.sqrt()) / 2.0);
        let plain = DenseSolver.solve(&sys, ModeRequest::modes(1)).unwrap();
        assert_eq!((plain.modes.shapes.shape(), plain.next_eigenvalue), ((2, 1), None));
        let only = DenseSolver.solve(&sys, ModeRequest::eigenvalues(1).with_certificate()).unwrap();
        assert_eq!(only.modes.shapes.shape(), (2, 0));
        assert!((only.modes.eigenvalues[0] - low).abs() < 1e-14);
        assert!((only.next_eigenvalue.unwrap() - high).abs() < 1e-14);
        // No further mode: the certificate is ∞.
        let all = DenseSolver.solve(&sys, ModeRequest::modes(2).with_certificate()).unwrap();
        assert_eq!(all.next_eigenvalue, Some(f64::INFINITY));
        assert_eq!(
            DenseSolver.lowest_with_next(&sys, 1).unwrap().1,
            DenseSolver.lowest(&sys, 2).unwrap().eigenvalues[1]
        );
    }
}
