//! The default, pure-nalgebra eigen-solver: Cholesky reduction to a standard symmetric problem.

use crate::modes::{apply_sign_rule, Modes};
use crate::solver::{check_count, EigenSolver, SolveError};
use crate::system::System;
use nalgebra::{Cholesky, DMatrix, DVector, SymmetricEigen};

/// Dense solver: M = LLᵀ, A = L⁻¹ K L⁻ᵀ, A = Y Λ Yᵀ, Φ = L⁻ᵀ Y. Needs no system library; O(n³).
#[derive(Debug, Clone, Copy, Default)]
pub struct DenseSolver;

impl EigenSolver for DenseSolver {
    fn name(&self) -> &'static str {
        "dense"
    }

    fn lowest(&self, system: &System, count: usize) -> Result<Modes, SolveError> {
        check_count(system, count)?;
        let chol = Cholesky::new(system.mass().clone())
            .ok_or(SolveError::MassNotPositiveDefinite { detail: None })?;
        let l = chol.l();
        // A = L⁻¹ K L⁻ᵀ via two triangular solves: X = L⁻¹ K, then A = (L⁻¹ Xᵀ)ᵀ.
        let x = l
            .solve_lower_triangular(system.stiffness())
            .ok_or_else(|| not_pd("zero pivot in L"))?;
        let a = l
            .solve_lower_triangular(&x.transpose())
            .ok_or_else(|| not_pd("zero pivot in L"))?;
        let a = (&a + a.transpose()) * 0.5;
        let eig = SymmetricEigen::try_new(a, f64::EPSILON, 0).ok_or(SolveError::Backend {
            backend: "dense",
            detail: "symmetric QR iteration did not converge".into(),
        })?;
        let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        order.truncate(count);
        let eigenvalues = DVector::from_iterator(count, order.iter().map(|&i| eig.eigenvalues[i]));
        let y = DMatrix::from_columns(
            &order
                .iter()
                .map(|&i| eig.eigenvectors.column(i))
                .collect::<Vec<_>>(),
        );
        let mut shapes = l
            .transpose()
            .solve_upper_triangular(&y)
            .ok_or_else(|| not_pd("zero pivot in Lᵀ"))?;
        if eigenvalues
            .iter()
            .chain(shapes.iter())
            .any(|v| !v.is_finite())
        {
            return Err(SolveError::Backend {
                backend: "dense",
                detail: "non-finite result".into(),
            });
        }
        apply_sign_rule(&mut shapes);
        Ok(Modes {
            eigenvalues,
            shapes,
        })
    }
}

fn not_pd(detail: &str) -> SolveError {
    SolveError::MassNotPositiveDefinite {
        detail: Some(detail.into()),
    }
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
        assert!(
            (phi.transpose() * &m * phi - DMatrix::identity(2, 2))
                .abs()
                .max()
                < 1e-13
        );
        let lam = DMatrix::from_diagonal(&modes.eigenvalues);
        assert!((phi.transpose() * &k * phi - lam).abs().max() < 1e-12);
    }

    #[test]
    fn rejects_indefinite_mass_and_bad_counts() {
        let sys = System::new(
            DMatrix::identity(2, 2),
            DMatrix::from_diagonal_element(2, 2, -1.0),
        )
        .unwrap();
        assert!(matches!(
            DenseSolver.lowest(&sys, 1),
            Err(SolveError::MassNotPositiveDefinite { .. })
        ));
        let sys = System::new(DMatrix::identity(2, 2), DMatrix::identity(2, 2)).unwrap();
        assert_eq!(
            DenseSolver.lowest(&sys, 3),
            Err(SolveError::TooManyModes {
                requested: 3,
                available: 2
            })
        );
        assert_eq!(DenseSolver.lowest(&sys, 0), Err(SolveError::NoModes));
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
}
