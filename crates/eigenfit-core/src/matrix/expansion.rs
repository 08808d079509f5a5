//! The expansion T = [I; −X] of a static condensation, and products through it.
//!
//! A model whose massless DOFs are condensed out works on the massed DOFs only: K_c = TᵀKT, and a
//! parameter derivative of K_c is Tᵀ(∂K)T. That product fills in densely (X is dense), yet every
//! use of it is a product with vectors: xᵀTᵀ∂KTy = (Tx)ᵀ∂K(Ty), and Tᵀ∂KTx = Tᵀ(∂K(Tx)), each
//! O(n_s·n_m + nnz(∂K)) — so [`SparseSymmetric::congruent`](super::SparseSymmetric::congruent)
//! keeps ∂K and T, never the product.

use nalgebra::DMatrix;

/// T = [I; −X] in the full model's numbering: the full vector of a condensed one is v at the
/// kept (massed) DOFs and −Xv at the massless ones.
#[derive(Debug, Clone, PartialEq)]
pub struct Expansion {
    full_dim: usize,
    kept: Vec<usize>,
    massless: Vec<usize>,
    /// Xᵀ (n_m × n_s): row a of X is column a here, contiguous.
    xt: DMatrix<f64>,
}

impl Expansion {
    /// T for a model of `full_dim` DOFs whose condensed DOF i is full DOF `kept[i]`, massless DOF a
    /// is full DOF `massless[a]`, and X (n_s × n_m) gives the massless DOFs' response −Xv.
    ///
    /// # Panics
    /// When the sizes disagree or an index is out of range: a bug in the caller, not user input.
    pub fn new(full_dim: usize, kept: Vec<usize>, massless: Vec<usize>, x: &DMatrix<f64>) -> Self {
        assert_eq!((x.nrows(), x.ncols()), (massless.len(), kept.len()), "X must be n_s × n_m");
        assert!(kept.iter().chain(&massless).all(|&j| j < full_dim), "a DOF beyond {full_dim}");
        Self { full_dim, kept, massless, xt: x.transpose() }
    }

    /// Number of DOFs of the full model.
    pub fn full_dim(&self) -> usize {
        self.full_dim
    }

    /// Number of DOFs of the condensed model (the massed ones).
    pub fn dim(&self) -> usize {
        self.kept.len()
    }

    /// T v: `v` (condensed) at the kept DOFs, −Xv at the massless ones. O(n_s·n_m).
    pub fn expand(&self, v: &[f64]) -> Vec<f64> {
        assert_eq!(v.len(), self.dim(), "a condensed vector has {} entries", self.dim());
        let mut full = vec![0.0; self.full_dim];
        for (&j, &value) in self.kept.iter().zip(v) {
            full[j] = value;
        }
        for (a, &j) in self.massless.iter().enumerate() {
            full[j] = -self.xt.column(a).iter().zip(v).map(|(x, v)| x * v).sum::<f64>();
        }
        full
    }

    /// `out += alpha · Tᵀ w` for a full vector `w`; the massless entries of `w` that are zero
    /// cost nothing (w = ∂K·Tx touches few DOFs).
    pub fn add_transposed(&self, alpha: f64, w: &[f64], out: &mut [f64]) {
        for (o, &j) in out.iter_mut().zip(&self.kept) {
            *o += alpha * w[j];
        }
        for (a, &j) in self.massless.iter().enumerate() {
            if w[j] != 0.0 {
                for (o, x) in out.iter_mut().zip(self.xt.column(a).iter()) {
                    *o -= alpha * w[j] * x;
                }
            }
        }
    }

    /// Tᵀ D T as a dense n_m × n_m matrix for a full-size `d` given densely — the reference, and
    /// the materialised form for callers that need every entry.
    pub fn congruence_dense(&self, d: &DMatrix<f64>) -> DMatrix<f64> {
        let (nm, n) = (self.dim(), self.full_dim);
        let mut t = DMatrix::<f64>::zeros(n, nm);
        for (i, &j) in self.kept.iter().enumerate() {
            t[(j, i)] = 1.0;
        }
        for (a, &j) in self.massless.iter().enumerate() {
            for i in 0..nm {
                t[(j, i)] = -self.xt[(i, a)];
            }
        }
        t.transpose() * d * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expansion_and_its_transpose_are_adjoint() {
        // 5 DOFs, 1 and 3 massless.
        let x = DMatrix::from_row_slice(2, 3, &[0.5, -1.0, 0.25, 2.0, 0.0, -0.75]);
        let t = Expansion::new(5, vec![0, 2, 4], vec![1, 3], &x);
        let v = [1.0, 2.0, -3.0];
        let full = t.expand(&v);
        assert_eq!(full, vec![1.0, -(0.5 - 2.0 - 0.75), 2.0, -(2.0 + 2.25), -3.0]);
        let w = [0.3, -1.2, 0.0, 0.7, 2.0];
        let mut tw = vec![0.0; 3];
        t.add_transposed(1.0, &w, &mut tw);
        let lhs: f64 = full.iter().zip(&w).map(|(a, b)| a * b).sum();
        let rhs: f64 = v.iter().zip(&tw).map(|(a, b)| a * b).sum();
        assert!((lhs - rhs).abs() < 1e-14, "{lhs} vs {rhs}");
    }
}
