//! The result of an eigen-solve: eigenvalues and mass-normalised mode shapes.

use crate::units::eigenvalue_to_hz;
use nalgebra::{DMatrix, DVector};

/// The lowest m modes of K φ = λ M φ: λ ascending, Φ (n×m) with ΦᵀMΦ = I and the sign rule of
/// [`apply_sign_rule`].
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// Eigenvalues λ = ω² in (rad/s)², ascending.
    pub eigenvalues: DVector<f64>,
    /// Mode shapes as columns (n×m), mass-normalised.
    pub shapes: DMatrix<f64>,
}

impl Modes {
    /// Number of modes m.
    pub fn count(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Natural frequencies in Hz.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues.iter().map(|&l| eigenvalue_to_hz(l)).collect()
    }

    /// Mode shape k as a slice of length n.
    pub fn shape(&self, k: usize) -> &[f64] {
        let n = self.shapes.nrows();
        &self.shapes.as_slice()[k * n..(k + 1) * n]
    }
}

/// Fixes the sign of each column: its largest-magnitude entry is made positive. Entries within
/// 1e-6 (relative) of the largest count as tied and the lowest index wins, so two backends that
/// differ only by round-off choose the same entry.
pub fn apply_sign_rule(shapes: &mut DMatrix<f64>) {
    for mut col in shapes.column_iter_mut() {
        let max = col.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if let Some(pivot) = col.iter().position(|v| v.abs() >= max * (1.0 - 1e-6)) {
            if col[pivot] < 0.0 {
                col.neg_mut();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_rule_prefers_lowest_index_among_ties() {
        let mut s = DMatrix::from_column_slice(3, 2, &[0.1, -0.5, 0.5, -1.0, 0.2, 0.3]);
        apply_sign_rule(&mut s);
        assert_eq!(s.column(0).as_slice(), &[-0.1, 0.5, -0.5]);
        assert_eq!(s.column(1).as_slice(), &[1.0, -0.2, -0.3]);
    }
}
