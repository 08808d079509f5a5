//! A sparse Cholesky factor held for many solves: the massless DOFs' stiffness K_ss of a
//! condensed model, solved once per vector expanded (see [`Expansion`](super::Expansion)).

use super::CscSymmetric;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use std::sync::Arc;

/// Below this ratio of a squared pivot of L to its diagonal entry of A, A is taken as singular
/// there (the dense condensation's test).
const SINGULAR_PIVOT_RATIO: f64 = 1e-12;

/// LLᵀ of a symmetric positive definite [`CscSymmetric`], after an AMD fill-reducing ordering.
#[derive(Debug, Clone)]
pub(crate) struct SparseCholesky {
    /// Shared by clones (faer's symbolic factor is not `Clone`).
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
}

impl SparseCholesky {
    /// The factor of `a`; `None` when `a` is not (numerically) positive definite: the
    /// factorisation fails, or a squared pivot falls below 1e-12 of its diagonal entry.
    pub(crate) fn factor(a: &CscSymmetric) -> Option<Self> {
        let n = a.dim();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
        let symbolic = a.symbolic_cholesky().ok()?;
        let mut values = vec![0.0; symbolic.len_val()];
        let req = symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        let mut buffer = MemBuffer::try_new(req).ok()?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                SparseColMatRef::new(pattern, a.values()),
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .ok()?;
        let factor = Self { symbolic: Arc::new(symbolic), values };
        // Pivots in the factor's order against the permuted diagonal of A.
        let perm = factor.symbolic.perm().map(|p| p.arrays().0.to_vec());
        let pivots = factor.pivots();
        let singular = pivots.iter().enumerate().any(|(j, &l)| {
            let original = perm.as_ref().map_or(j, |p| p[j]);
            let d = a.get(original, original).abs();
            !(l * l > SINGULAR_PIVOT_RATIO * d && l.is_finite())
        });
        (!singular).then_some(factor)
    }

    /// L's diagonal, in the factor's order.
    fn pivots(&self) -> Vec<f64> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                s.col_ptr()[..s.ncols()].iter().map(|&p| self.values[p]).collect()
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let mut out = Vec::with_capacity(s.nrows());
                for (sn, (&begin, &end)) in s.supernode_begin().iter().zip(s.supernode_end()).enumerate() {
                    let cols = end - begin;
                    let block = &self.values[s.col_ptr_for_val()[sn]..s.col_ptr_for_val()[sn + 1]];
                    let rows = block.len() / cols;
                    out.extend((0..cols).map(|c| block[c * rows + c]));
                }
                out
            }
        }
    }

    /// x ← A⁻¹x.
    pub(crate) fn solve_in_place(&self, x: &mut [f64]) {
        let n = x.len();
        let req: StackReq = self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq);
        let mut buffer = MemBuffer::new(req);
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(&mut buffer),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_refuses_a_singular_matrix() {
        let a = CscSymmetric::from_triplets(
            3,
            [(0, 0, 4.0), (1, 0, -1.0), (1, 1, 3.0), (2, 1, -1.0), (2, 2, 2.0)],
        );
        let f = SparseCholesky::factor(&a).expect("positive definite");
        let mut x = vec![1.0, -2.0, 0.5];
        let b = x.clone();
        f.solve_in_place(&mut x);
        let mut ax = vec![0.0; 3];
        a.mul_add(1.0, &x, &mut ax);
        assert!(ax.iter().zip(&b).all(|(u, v)| (u - v).abs() < 1e-14), "{ax:?} vs {b:?}");
        let singular = CscSymmetric::from_triplets(2, [(0, 0, 1.0), (1, 0, 1.0), (1, 1, 1.0)]);
        assert!(SparseCholesky::factor(&singular).is_none());
    }
}
