//! General sparse symmetric matrices in compressed-column form, one triangle stored: the storage
//! of models exported from any finite-element tool (plates, shells, solids), which are neither
//! small enough for dense storage (10⁵ DOFs: 80 GB per matrix) nor banded.
//!
//! Only the upper triangle (row ≤ column) is kept, rows sorted and unique within each column —
//! the layout faer's sparse Cholesky reads with `Side::Upper`, so a factorisation needs no copy.

use crate::matrix::{BandedSymmetric, SparseSymmetric};
use nalgebra::DMatrix;

/// Symmetric n×n matrix, upper triangle in compressed-column storage (CSC).
///
/// ```
/// use eigenfit_core::matrix::CscSymmetric;
///
/// // [[2, -1], [-1, 2]]: the entry (1, 0) lands in the upper triangle, duplicates add up.
/// let a = CscSymmetric::from_triplets(2, [(0, 0, 2.0), (1, 0, -1.0), (1, 1, 1.5), (1, 1, 0.5)]);
/// assert_eq!(a.nnz(), 3);
/// let mut y = vec![0.0; 2];
/// a.mul_add(1.0, &[1.0, 1.0], &mut y);
/// assert_eq!(y, vec![1.0, 1.0]);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CscSymmetric {
    dim: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

impl CscSymmetric {
    /// Builds the matrix from entries `(i, j, value)` of either triangle; an entry (i, j) with
    /// i > j stands for (j, i) as well, duplicates add up. Explicit zeros are kept (they fix a
    /// pattern shared by several matrices).
    ///
    /// # Panics
    /// When an index is out of range: callers validate user input first (the matrices plugin
    /// names the file and line).
    pub fn from_triplets(dim: usize, entries: impl IntoIterator<Item = (usize, usize, f64)>) -> Self {
        let mut upper: Vec<(usize, usize, f64)> = entries
            .into_iter()
            .map(|(i, j, v)| {
                assert!(i < dim && j < dim, "entry ({i}, {j}) outside {dim}×{dim}");
                if i <= j {
                    (j, i, v)
                } else {
                    (i, j, v)
                }
            })
            .collect();
        // (column, row) order.
        upper.sort_unstable_by_key(|&(c, r, _)| (c, r));
        let mut col_ptr = vec![0; dim + 1];
        let mut row_idx = Vec::with_capacity(upper.len());
        let mut values: Vec<f64> = Vec::with_capacity(upper.len());
        let mut last = None;
        for (c, r, v) in upper {
            if last == Some((c, r)) {
                *values.last_mut().expect("a previous entry") += v;
                continue;
            }
            last = Some((c, r));
            row_idx.push(r);
            values.push(v);
            col_ptr[c + 1] += 1;
        }
        for c in 0..dim {
            col_ptr[c + 1] += col_ptr[c];
        }
        Self { dim, col_ptr, row_idx, values }
    }

    /// An n×n matrix with the pattern of `self` and `other` together, values `a·self + b·other`.
    pub fn combination(a: f64, this: &Self, b: f64, other: &Self) -> Self {
        assert_eq!(this.dim, other.dim, "sparse matrices of different size");
        let n = this.dim;
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::with_capacity(this.nnz().max(other.nnz()));
        let mut values = Vec::with_capacity(row_idx.capacity());
        for c in 0..n {
            let (x, y) = (this.column(c), other.column(c));
            let (mut p, mut q) = (0, 0);
            while p < x.0.len() || q < y.0.len() {
                let rx = x.0.get(p).copied().unwrap_or(usize::MAX);
                let ry = y.0.get(q).copied().unwrap_or(usize::MAX);
                let r = rx.min(ry);
                let mut v = 0.0;
                if rx == r {
                    v += a * x.1[p];
                    p += 1;
                }
                if ry == r {
                    v += b * y.1[q];
                    q += 1;
                }
                row_idx.push(r);
                values.push(v);
            }
            col_ptr.push(row_idx.len());
        }
        Self { dim: n, col_ptr, row_idx, values }
    }

    /// Adds `alpha · other` into `self`, whose pattern must contain `other`'s (a matrix built
    /// by [`combination`](Self::combination) with it, for instance). O(nnz). False, with `self`
    /// partly updated, when an entry of `other` has no place in `self`.
    pub fn add_scaled_within(&mut self, alpha: f64, other: &Self) -> bool {
        if self.dim != other.dim {
            return false;
        }
        for c in 0..self.dim {
            let (rows, range) = (&self.row_idx[self.col_ptr[c]..self.col_ptr[c + 1]], self.col_ptr[c]);
            let (orows, ovals) = other.column(c);
            let mut p = 0;
            for (&r, &v) in orows.iter().zip(ovals) {
                while p < rows.len() && rows[p] < r {
                    p += 1;
                }
                if p == rows.len() || rows[p] != r {
                    return false;
                }
                self.values[range + p] += alpha * v;
            }
        }
        true
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of stored (upper-triangle) entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Column pointers (n + 1 entries).
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// Row index of every stored entry, sorted within each column, each ≤ its column.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// faer's symbolic Cholesky of this pattern (upper triangle, AMD fill-reducing ordering):
    /// the analysis every sparse factorisation of the matrix starts from.
    pub(crate) fn symbolic_cholesky(
        &self,
    ) -> Result<faer::sparse::linalg::cholesky::SymbolicCholesky<usize>, faer::sparse::FaerError> {
        use faer::sparse::linalg::cholesky::{
            factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
        };
        let n = self.dim();
        let pattern =
            faer::sparse::SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        factorize_symbolic_cholesky(
            pattern,
            faer::Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
    }

    /// Value of every stored entry.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Values, to overwrite in place (the pattern stays).
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Whether `other` has exactly the same pattern.
    pub fn same_pattern(&self, other: &Self) -> bool {
        self.dim == other.dim && self.col_ptr == other.col_ptr && self.row_idx == other.row_idx
    }

    /// (rows, values) of column `c`'s upper part.
    pub fn column(&self, c: usize) -> (&[usize], &[f64]) {
        let range = self.col_ptr[c]..self.col_ptr[c + 1];
        (&self.row_idx[range.clone()], &self.values[range])
    }

    /// Entry (i, j) (either triangle); zero where nothing is stored. O(log of the column length).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (r, c) = if i <= j { (i, j) } else { (j, i) };
        let (rows, values) = self.column(c);
        rows.binary_search(&r).map_or(0.0, |p| values[p])
    }

    /// Computes `out += alpha · A x` (both triangles).
    pub fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        for c in 0..self.dim {
            let (rows, values) = self.column(c);
            let xc = alpha * x[c];
            let mut acc = 0.0;
            for (&r, &v) in rows.iter().zip(values) {
                if r == c {
                    out[c] += v * xc;
                } else {
                    out[r] += v * xc;
                    acc += v * x[r];
                }
            }
            out[c] += alpha * acc;
        }
    }

    /// Σᵢⱼ |Aᵢⱼ|·|xᵢ|·|xⱼ| (both triangles): how much the entries' own rounding can move xᵀAx.
    pub fn abs_quadratic(&self, x: &[f64]) -> f64 {
        let mut sum = 0.0;
        for c in 0..self.dim {
            let (rows, values) = self.column(c);
            let xc = x[c].abs();
            for (&r, &v) in rows.iter().zip(values) {
                let term = v.abs() * x[r].abs() * xc;
                sum += if r == c { term } else { 2.0 * term };
            }
        }
        sum
    }

    /// Largest |Aᵢⱼ|.
    pub fn amax(&self) -> f64 {
        self.values.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
    }

    /// ‖A‖∞: the largest absolute row sum over both triangles.
    pub fn inf_norm(&self) -> f64 {
        let mut sums = vec![0.0; self.dim];
        for c in 0..self.dim {
            let (rows, values) = self.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                sums[c] += v.abs();
                if r != c {
                    sums[r] += v.abs();
                }
            }
        }
        sums.into_iter().fold(0.0, f64::max)
    }

    /// Largest diagonal entry (0 for an empty diagonal).
    pub fn diagonal_max(&self) -> f64 {
        (0..self.dim).map(|c| self.get(c, c)).fold(0.0_f64, f64::max)
    }

    /// First entry `(row, col, value)` that is NaN or infinite.
    pub fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        (0..self.dim).find_map(|c| {
            let (rows, values) = self.column(c);
            rows.iter().zip(values).find(|(_, v)| !v.is_finite()).map(|(&r, &v)| (r, c, v))
        })
    }

    /// Dense copy (tests, small models).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.dim, self.dim);
        for c in 0..self.dim {
            let (rows, values) = self.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                m[(r, c)] += v;
                if r != c {
                    m[(c, r)] += v;
                }
            }
        }
        m
    }

    /// Sparse copy of a dense symmetric matrix (upper triangle, nonzero entries).
    pub fn from_dense(a: &DMatrix<f64>) -> Self {
        let n = a.nrows();
        Self::from_triplets(
            n,
            (0..n).flat_map(|j| (0..=j).map(move |i| (i, j))).filter_map(|(i, j)| {
                let v = a[(i, j)];
                (v != 0.0).then_some((i, j, v))
            }),
        )
    }

    /// Band copy in this numbering, or `None` when its band would hold more than `max_entries`
    /// values (a matrix whose nonzeros lie far from the diagonal).
    pub fn to_banded_within(&self, max_entries: usize) -> Option<BandedSymmetric> {
        let n = self.dim;
        let b = (0..n).map(|j| self.column(j).0.first().map_or(0, |&i| j - i)).max().unwrap_or(0);
        if n.saturating_mul(b + 1) > max_entries {
            return None;
        }
        let mut a = BandedSymmetric::zeros(n, b);
        for j in 0..n {
            let (rows, values) = self.column(j);
            for (&i, &v) in rows.iter().zip(values) {
                a.add(i, j, v);
            }
        }
        Some(a)
    }

    /// Sparse copy of a band matrix (nonzero entries).
    pub fn from_banded(a: &BandedSymmetric) -> Self {
        let (n, b) = (a.dim(), a.bandwidth());
        Self::from_triplets(
            n,
            (0..n).flat_map(|j| (j.saturating_sub(b)..=j).map(move |i| (i, j))).filter_map(|(i, j)| {
                let v = a.get(i, j);
                (v != 0.0).then_some((i, j, v))
            }),
        )
    }

    /// The same matrix as upper-triangle triplets ([`SparseSymmetric`], the form of parameter
    /// derivatives), zeros left out.
    pub fn to_sparse_symmetric(&self) -> SparseSymmetric {
        let mut s = SparseSymmetric::zeros(self.dim);
        for c in 0..self.dim {
            let (rows, values) = self.column(c);
            for (&r, &v) in rows.iter().zip(values) {
                if v != 0.0 {
                    s.add(r, c, v);
                }
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> CscSymmetric {
        CscSymmetric::from_triplets(
            4,
            [(0, 0, 4.0), (2, 0, -1.0), (0, 2, -0.5), (3, 3, 2.0), (1, 1, 3.0), (3, 1, 0.25)],
        )
    }

    #[test]
    fn triplets_fold_to_upper_triangle_and_add_duplicates() {
        let a = sample();
        assert_eq!(a.nnz(), 5);
        assert_eq!(a.get(2, 0), -1.5);
        assert_eq!(a.get(0, 2), -1.5);
        let d = a.to_dense();
        assert_eq!(d, d.transpose());
        assert_eq!(CscSymmetric::from_dense(&d), a);
        assert_eq!(a.to_sparse_symmetric().to_dense(), d);
        let row_sums = d.row_iter().map(|r| r.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max);
        assert_eq!(a.inf_norm(), row_sums);
    }

    #[test]
    fn product_and_combination_match_dense() {
        let a = sample();
        let b = CscSymmetric::from_triplets(4, [(0, 1, 1.0), (2, 2, 5.0), (0, 0, 1.0)]);
        let x = [1.0, -2.0, 0.5, 3.0];
        let mut y = vec![0.5; 4];
        a.mul_add(2.0, &x, &mut y);
        let expect = nalgebra::DVector::from_element(4, 0.5)
            + a.to_dense() * nalgebra::DVector::from_row_slice(&x) * 2.0;
        assert_eq!(y, expect.as_slice());
        let mut c = CscSymmetric::combination(1.0, &a, -0.5, &b);
        assert_eq!(c.to_dense(), a.to_dense() - b.to_dense() * 0.5);
        assert!(c.add_scaled_within(0.5, &b));
        assert_eq!(c.to_dense(), a.to_dense());
        assert!(!a.clone().add_scaled_within(1.0, &b), "b's (0, 1) has no place in a");
    }

    #[test]
    fn band_copy_is_exact() {
        let mut band = BandedSymmetric::zeros(3, 1);
        band.add(0, 0, 2.0);
        band.add(1, 0, -1.0);
        band.add(2, 2, 1.0);
        assert_eq!(CscSymmetric::from_banded(&band).to_dense(), band.to_dense());
    }
}
