//! A small symmetric sparse matrix in coordinate form, for parameter derivatives ∂K/∂pᵢ, ∂M/∂pᵢ.
//!
//! A bearing stiffness touches one diagonal entry and a beam element a 4×4 block, so a derivative
//! is a handful of entries: storing it densely would make every sensitivity cost O(n²).

use nalgebra::{DMatrix, DVector};

/// Symmetric n×n matrix stored as upper-triangle triplets `(row ≤ col, value)`; duplicates add up.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SparseSymmetric {
    dim: usize,
    entries: Vec<(usize, usize, f64)>,
}

impl SparseSymmetric {
    /// An all-zero n×n matrix.
    pub fn zeros(dim: usize) -> Self {
        Self { dim, entries: Vec::new() }
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Stored upper-triangle entries `(row, col, value)` with `row ≤ col`.
    pub fn entries(&self) -> &[(usize, usize, f64)] {
        &self.entries
    }

    /// True when no entry is stored.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Adds `value` at (i, j) and, implicitly, at (j, i).
    ///
    /// # Panics
    /// When an index is out of range: that is a bug in the model plugin, not user input.
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        assert!(i < self.dim && j < self.dim, "entry ({i}, {j}) outside {0}×{0}", self.dim);
        let (r, c) = if i <= j { (i, j) } else { (j, i) };
        self.entries.push((r, c, value));
    }

    /// Adds a dense symmetric block `block` at the global indices `dofs` (element assembly).
    pub fn add_block(&mut self, dofs: &[usize], block: &DMatrix<f64>) {
        for (a, &i) in dofs.iter().enumerate() {
            for (b, &j) in dofs.iter().enumerate().skip(a) {
                let v = block[(a, b)];
                if v != 0.0 {
                    if i == j && a != b {
                        // Two element DOFs on the same global DOF: both triangles land on the diagonal.
                        self.add(i, j, 2.0 * v);
                    } else {
                        self.add(i, j, v);
                    }
                }
            }
        }
    }

    /// Quadratic form xᵀ A y.
    pub fn bilinear(&self, x: &[f64], y: &[f64]) -> f64 {
        self.entries
            .iter()
            .map(|&(i, j, v)| if i == j { v * x[i] * y[i] } else { v * (x[i] * y[j] + x[j] * y[i]) })
            .sum()
    }

    /// Computes `out += alpha · A x`.
    pub fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        for &(i, j, v) in &self.entries {
            out[i] += alpha * v * x[j];
            if i != j {
                out[j] += alpha * v * x[i];
            }
        }
    }

    /// A x as a new vector.
    pub fn mul_vector(&self, x: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(self.dim);
        self.mul_add(1.0, x.as_slice(), out.as_mut_slice());
        out
    }

    /// Dense copy (tests, small models).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.dim, self.dim);
        for &(i, j, v) in &self.entries {
            m[(i, j)] += v;
            if i != j {
                m[(j, i)] += v;
            }
        }
        m
    }

    /// Sparse copy of a dense symmetric matrix, keeping the entries with |a| > `drop_below`.
    pub fn from_dense(a: &DMatrix<f64>, drop_below: f64) -> Self {
        let mut s = Self::zeros(a.nrows());
        for j in 0..a.ncols() {
            for i in 0..=j {
                let v = 0.5 * (a[(i, j)] + a[(j, i)]);
                if v.abs() > drop_below {
                    s.add(i, j, v);
                }
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_and_product_match_dense() {
        let mut s = SparseSymmetric::zeros(3);
        s.add(0, 0, 2.0);
        s.add(2, 1, -1.5);
        s.add(1, 2, 0.5);
        let d = s.to_dense();
        assert_eq!(d[(1, 2)], -1.0);
        assert_eq!(d[(2, 1)], -1.0);
        let x = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let y = DVector::from_vec(vec![-1.0, 0.5, 4.0]);
        assert!((s.bilinear(x.as_slice(), y.as_slice()) - x.dot(&(&d * &y))).abs() < 1e-14);
        assert_eq!(s.mul_vector(&x), &d * &x);
        assert_eq!(SparseSymmetric::from_dense(&d, 0.0).to_dense(), d);
    }

    #[test]
    fn block_on_repeated_dof_counts_both_triangles() {
        let block = DMatrix::from_row_slice(2, 2, &[1.0, 3.0, 3.0, 2.0]);
        let mut s = SparseSymmetric::zeros(1);
        s.add_block(&[0, 0], &block);
        assert_eq!(s.to_dense()[(0, 0)], 1.0 + 3.0 + 3.0 + 2.0);
    }
}
