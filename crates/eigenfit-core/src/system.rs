//! Assembled matrices K, M of a structure at one parameter vector, and their parameter derivatives.

use crate::sparse::SparseSymmetric;
use nalgebra::DMatrix;
use thiserror::Error;

/// Why a pair (K, M) is not a valid symmetric eigenproblem.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SystemError {
    /// K or M is not square, or they differ in size.
    #[error("K is {k_rows}×{k_cols} and M is {m_rows}×{m_cols}: both must be the same square size")]
    Shape { k_rows: usize, k_cols: usize, m_rows: usize, m_cols: usize },
    /// The system has no degree of freedom.
    #[error("the system has no degree of freedom")]
    Empty,
    /// An entry is NaN or infinite.
    #[error("{matrix}[{row}, {col}] is {value}: every entry must be finite")]
    NonFinite { matrix: &'static str, row: usize, col: usize, value: f64 },
    /// A matrix is not symmetric.
    #[error("{matrix} is not symmetric: [{row}, {col}] = {a} but [{col}, {row}] = {b}")]
    NotSymmetric { matrix: &'static str, row: usize, col: usize, a: f64, b: f64 },
}

/// Stiffness K and mass M of a structure (n×n, symmetric; M positive definite for a solve).
#[derive(Debug, Clone, PartialEq)]
pub struct System {
    stiffness: DMatrix<f64>,
    mass: DMatrix<f64>,
}

impl System {
    /// Checks shape, finiteness and symmetry (to 1e-12 relative) and builds the system.
    pub fn new(stiffness: DMatrix<f64>, mass: DMatrix<f64>) -> Result<Self, SystemError> {
        let (n, c) = stiffness.shape();
        if n != c || mass.shape() != (n, n) {
            return Err(SystemError::Shape {
                k_rows: n,
                k_cols: c,
                m_rows: mass.nrows(),
                m_cols: mass.ncols(),
            });
        }
        if n == 0 {
            return Err(SystemError::Empty);
        }
        check_matrix("K", &stiffness)?;
        check_matrix("M", &mass)?;
        Ok(Self { stiffness, mass })
    }

    /// Number of degrees of freedom n.
    pub fn dofs(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Stiffness matrix K.
    pub fn stiffness(&self) -> &DMatrix<f64> {
        &self.stiffness
    }

    /// Mass matrix M.
    pub fn mass(&self) -> &DMatrix<f64> {
        &self.mass
    }

    /// Consumes the system, returning (K, M).
    pub fn into_parts(self) -> (DMatrix<f64>, DMatrix<f64>) {
        (self.stiffness, self.mass)
    }
}

fn check_matrix(name: &'static str, a: &DMatrix<f64>) -> Result<(), SystemError> {
    let scale = a.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            let v = a[(i, j)];
            if !v.is_finite() {
                return Err(SystemError::NonFinite { matrix: name, row: i, col: j, value: v });
            }
            if i < j {
                let w = a[(j, i)];
                if (v - w).abs() > 1e-12 * scale {
                    return Err(SystemError::NotSymmetric { matrix: name, row: i, col: j, a: v, b: w });
                }
            }
        }
    }
    Ok(())
}

/// ∂K/∂pᵢ and ∂M/∂pᵢ for one parameter, sparse.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemDerivative {
    /// ∂K/∂pᵢ.
    pub stiffness: SparseSymmetric,
    /// ∂M/∂pᵢ.
    pub mass: SparseSymmetric,
}

impl SystemDerivative {
    /// Zero derivative of an n-DOF system.
    pub fn zeros(dim: usize) -> Self {
        Self { stiffness: SparseSymmetric::zeros(dim), mass: SparseSymmetric::zeros(dim) }
    }

    /// φᵀ(∂K − λ ∂M)ψ: the building block of every eigen-sensitivity.
    pub fn shifted_bilinear(&self, lambda: f64, phi: &[f64], psi: &[f64]) -> f64 {
        let k = self.stiffness.bilinear(phi, psi);
        if self.mass.is_empty() {
            k
        } else {
            k - lambda * self.mass.bilinear(phi, psi)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_matrices_with_location() {
        let k = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 0.0, 1.0]);
        let m = DMatrix::identity(2, 2);
        assert_eq!(
            System::new(k, m.clone()).unwrap_err().to_string(),
            "K is not symmetric: [0, 1] = 2 but [1, 0] = 0"
        );
        let k = DMatrix::from_row_slice(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]);
        assert!(matches!(
            System::new(k, m.clone()),
            Err(SystemError::NonFinite { matrix: "K", row: 0, col: 0, .. })
        ));
        assert!(matches!(System::new(DMatrix::identity(3, 3), m), Err(SystemError::Shape { .. })));
        assert_eq!(System::new(DMatrix::zeros(0, 0), DMatrix::zeros(0, 0)), Err(SystemError::Empty));
    }
}
