//! A small symmetric sparse matrix in coordinate form, for parameter derivatives ∂K/∂pᵢ, ∂M/∂pᵢ.
//!
//! A bearing stiffness touches one diagonal entry and a beam element a 4×4 block, so a derivative
//! is a handful of entries: storing it densely would make every sensitivity cost O(n²).
//!
//! A condensed model's derivative Tᵀ∂KT (see [`Expansion`]) is held as ∂K and T: products go
//! through T, and the dense triplets are only formed (once, on demand) for [`SparseSymmetric::entries`].

use super::expansion::Expansion;
use nalgebra::{DMatrix, DVector};
use std::sync::{Arc, OnceLock};

/// Symmetric n×n matrix stored as upper-triangle triplets `(row ≤ col, value)`; duplicates add up.
/// It may hold, besides, a congruent part Tᵀ D T ([`SparseSymmetric::congruent`]).
#[derive(Debug, Clone, Default)]
pub struct SparseSymmetric {
    dim: usize,
    entries: Vec<(usize, usize, f64)>,
    /// D (full size) and T of a congruent part Tᵀ D T added to `entries`.
    congruent: Option<(Box<SparseSymmetric>, Arc<Expansion>)>,
    /// `entries` with the congruent part's triplets, formed on the first call of `entries()`.
    materialised: OnceLock<Vec<(usize, usize, f64)>>,
}

impl PartialEq for SparseSymmetric {
    fn eq(&self, other: &Self) -> bool {
        self.dim == other.dim && self.entries == other.entries && self.congruent == other.congruent
    }
}

impl SparseSymmetric {
    /// An all-zero n×n matrix.
    pub fn zeros(dim: usize) -> Self {
        Self { dim, entries: Vec::new(), congruent: None, materialised: OnceLock::new() }
    }

    /// Tᵀ D T (n_m × n_m) for a full-size `d` and the expansion `t`, kept as `d` and `t`: a
    /// bilinear form or product costs one or two expansions (O(n_s·n_m)) and O(nnz(D)), where the
    /// product itself would be dense.
    ///
    /// # Panics
    /// When `d` is not of `t`'s full size: a bug in the caller.
    pub fn congruent(d: SparseSymmetric, t: Arc<Expansion>) -> Self {
        assert_eq!(d.dim(), t.full_dim(), "D must be of T's full size");
        assert!(d.congruent.is_none(), "D must be plain triplets");
        let mut s = Self::zeros(t.dim());
        if !d.is_empty() {
            s.congruent = Some((Box::new(d), t));
        }
        s
    }

    /// The expansion T of a congruent part, if any (several matrices built on one T share it).
    pub fn expansion(&self) -> Option<&Arc<Expansion>> {
        self.congruent.as_ref().map(|(_, t)| t)
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Upper-triangle entries `(row, col, value)` with `row ≤ col`; with a congruent part, its
    /// (dense) triplets too, formed on the first call.
    pub fn entries(&self) -> &[(usize, usize, f64)] {
        match &self.congruent {
            None => &self.entries,
            Some((d, t)) => self.materialised.get_or_init(|| {
                let dense = t.congruence_dense(&d.to_dense());
                let mut all = self.entries.clone();
                for j in 0..self.dim {
                    for i in 0..=j {
                        let v = 0.5 * (dense[(i, j)] + dense[(j, i)]);
                        if v != 0.0 {
                            all.push((i, j, v));
                        }
                    }
                }
                all
            }),
        }
    }

    /// True when no entry is stored.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty() && self.congruent.is_none()
    }

    /// Adds `value` at (i, j) and, implicitly, at (j, i).
    ///
    /// # Panics
    /// When an index is out of range: that is a bug in the model plugin, not user input.
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        assert!(i < self.dim && j < self.dim, "entry ({i}, {j}) outside {0}×{0}", self.dim);
        let (r, c) = if i <= j { (i, j) } else { (j, i) };
        self.entries.push((r, c, value));
        self.materialised = OnceLock::new();
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
        let plain: f64 = self
            .entries
            .iter()
            .map(|&(i, j, v)| if i == j { v * x[i] * y[i] } else { v * (x[i] * y[j] + x[j] * y[i]) })
            .sum();
        match &self.congruent {
            None => plain,
            Some((d, t)) => {
                let tx = t.expand(x);
                // xᵀTᵀDTx, the common case (an eigenvalue's derivative), expands once.
                let cross =
                    if std::ptr::eq(x, y) { d.bilinear(&tx, &tx) } else { d.bilinear(&tx, &t.expand(y)) };
                plain + cross
            }
        }
    }

    /// xᵀ A y with the expansions Tx, Ty given (the full vectors of x and y under this matrix's
    /// [`expansion`](Self::expansion)): the shared work of many derivatives built on one T done once.
    /// Without a congruent part the full vectors are not read.
    pub fn bilinear_expanded(&self, x: &[f64], y: &[f64], tx: &[f64], ty: &[f64]) -> f64 {
        let plain: f64 = self
            .entries
            .iter()
            .map(|&(i, j, v)| if i == j { v * x[i] * y[i] } else { v * (x[i] * y[j] + x[j] * y[i]) })
            .sum();
        plain + self.congruent.as_ref().map_or(0.0, |(d, _)| d.bilinear(tx, ty))
    }

    /// Computes `out += alpha · A x`.
    pub fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        match &self.congruent {
            None => self.plain_mul_add(alpha, x, out),
            Some((_, t)) => self.mul_add_expanded(alpha, x, &t.expand(x), out),
        }
    }

    /// [`mul_add`](Self::mul_add) with the expansion Tx given (see [`bilinear_expanded`](Self::bilinear_expanded)).
    pub fn mul_add_expanded(&self, alpha: f64, x: &[f64], tx: &[f64], out: &mut [f64]) {
        self.plain_mul_add(alpha, x, out);
        if let Some((d, t)) = &self.congruent {
            let mut w = vec![0.0; tx.len()];
            d.plain_mul_add(1.0, tx, &mut w);
            t.add_transposed(alpha, &w, out);
        }
    }

    fn plain_mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
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
        let mut m = match &self.congruent {
            None => DMatrix::zeros(self.dim, self.dim),
            Some((d, t)) => t.congruence_dense(&d.to_dense()),
        };
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

    #[test]
    fn a_congruent_part_acts_as_t_transposed_d_t() {
        // 6 DOFs, 1, 3 and 4 massless; D touches kept and massless DOFs, off the diagonal too.
        let x = DMatrix::from_row_slice(3, 3, &[0.5, -1.0, 0.25, 2.0, 0.0, -0.75, 0.1, 0.3, -0.2]);
        let t = Arc::new(Expansion::new(6, vec![0, 2, 5], vec![1, 3, 4], &x));
        let mut d = SparseSymmetric::zeros(6);
        for (i, j, v) in [(1, 0, -0.3), (1, 1, 0.3), (3, 3, 0.7), (4, 2, 0.2), (5, 4, -0.4), (5, 5, 1.1)] {
            d.add(i, j, v);
        }
        let reference = t.congruence_dense(&d.to_dense());
        let mut s = SparseSymmetric::congruent(d, Arc::clone(&t));
        s.add(0, 2, 0.9);
        let mut expected = reference.clone();
        expected[(0, 2)] += 0.9;
        expected[(2, 0)] += 0.9;
        assert!((s.to_dense() - &expected).amax() < 1e-14);
        let mut from_entries = SparseSymmetric::zeros(3);
        for &(i, j, v) in s.entries() {
            from_entries.add(i, j, v);
        }
        assert!((from_entries.to_dense() - &expected).amax() < 1e-14);
        let (u, w) = (DVector::from_vec(vec![1.0, -2.0, 0.5]), DVector::from_vec(vec![0.3, 0.4, -1.5]));
        let exact = u.dot(&(&expected * &w));
        assert!((s.bilinear(u.as_slice(), w.as_slice()) - exact).abs() < 1e-14);
        let (tu, tw) = (t.expand(u.as_slice()), t.expand(w.as_slice()));
        assert!((s.bilinear_expanded(u.as_slice(), w.as_slice(), &tu, &tw) - exact).abs() < 1e-14);
        assert!((s.mul_vector(&u) - &expected * &u).amax() < 1e-14);
    }
}
