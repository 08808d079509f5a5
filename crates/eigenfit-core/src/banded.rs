//! Symmetric band matrices and their Cholesky factor, for large beam-like models.
//!
//! A beam mesh couples each node only to its neighbours: with two DOFs per node every nonzero
//! K or M entry lies within 3 of the diagonal (half-bandwidth 3). Stored by band, a matrix costs
//! O(n·b) memory, a product O(n·b) and a Cholesky factorisation O(n·b²), against O(n²) and
//! O(n³) dense.

use nalgebra::DMatrix;

/// Symmetric n×n matrix with half-bandwidth b: entries with |i − j| > b are zero.
///
/// The lower band is stored column by column: entry (i, j) with j ≤ i ≤ j + b lives at
/// `data[j·(b + 1) + (i − j)]` (rows past n − 1 in the last columns are padding, kept at zero).
#[derive(Debug, Clone, PartialEq)]
pub struct BandedSymmetric {
    dim: usize,
    bandwidth: usize,
    data: Vec<f64>,
}

impl BandedSymmetric {
    /// An all-zero n×n matrix of half-bandwidth `bandwidth`.
    pub fn zeros(dim: usize, bandwidth: usize) -> Self {
        Self { dim, bandwidth, data: vec![0.0; dim * (bandwidth + 1)] }
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Half-bandwidth b.
    pub fn bandwidth(&self) -> usize {
        self.bandwidth
    }

    /// The band storage (see the type's documentation for the layout).
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    #[inline]
    fn index(&self, i: usize, j: usize) -> Option<usize> {
        let (r, c) = if i >= j { (i, j) } else { (j, i) };
        (r < self.dim && r - c <= self.bandwidth).then(|| c * (self.bandwidth + 1) + (r - c))
    }

    /// Entry (i, j); zero outside the band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.index(i, j).map_or(0.0, |k| self.data[k])
    }

    /// Adds `value` at (i, j) and, implicitly, at (j, i).
    ///
    /// # Panics
    /// When (i, j) lies outside the matrix or the band: a bug in the model plugin, not user input.
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        let k = self.index(i, j).unwrap_or_else(|| {
            panic!("entry ({i}, {j}) outside the {0}×{0} band of half-width {1}", self.dim, self.bandwidth)
        });
        self.data[k] += value;
    }

    /// The same matrix stored with a wider band (`bandwidth` ≥ the current one).
    pub fn widened(&self, bandwidth: usize) -> Self {
        if bandwidth <= self.bandwidth {
            return self.clone();
        }
        let mut out = Self::zeros(self.dim, bandwidth);
        for j in 0..self.dim {
            for d in 0..=self.bandwidth.min(self.dim - 1 - j) {
                out.data[j * (bandwidth + 1) + d] = self.data[j * (self.bandwidth + 1) + d];
            }
        }
        out
    }

    /// Largest |aᵢⱼ|.
    pub fn amax(&self) -> f64 {
        self.data.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
    }

    /// Largest diagonal entry.
    pub fn diagonal_max(&self) -> f64 {
        (0..self.dim).map(|j| self.data[j * (self.bandwidth + 1)]).fold(f64::NEG_INFINITY, f64::max)
    }

    /// The first non-finite entry as (row, col, value), if any.
    pub fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        let w = self.bandwidth + 1;
        self.data.iter().position(|v| !v.is_finite()).map(|k| (k / w + k % w, k / w, self.data[k]))
    }

    /// `self + alpha · other` (the band is the wider of the two).
    pub fn add_scaled(&self, alpha: f64, other: &Self) -> Self {
        assert_eq!(self.dim, other.dim, "band matrices of different size");
        let b = self.bandwidth.max(other.bandwidth);
        let mut out = self.widened(b);
        for j in 0..self.dim {
            for d in 0..=other.bandwidth.min(self.dim - 1 - j) {
                out.data[j * (b + 1) + d] += alpha * other.data[j * (other.bandwidth + 1) + d];
            }
        }
        out
    }

    /// Computes `out += alpha · A x`.
    pub fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        let (n, w) = (self.dim, self.bandwidth + 1);
        debug_assert!(x.len() == n && out.len() == n);
        for j in 0..n {
            let col = &self.data[j * w..j * w + w.min(n - j)];
            let xj = alpha * x[j];
            out[j] += col[0] * xj;
            let mut acc = 0.0;
            for (d, &a) in col.iter().enumerate().skip(1) {
                out[j + d] += a * xj;
                acc += a * x[j + d];
            }
            out[j] += alpha * acc;
        }
    }

    /// A X for every column of `x` (n×p), into `out` (n×p, overwritten).
    pub fn mul_columns(&self, x: &DMatrix<f64>, out: &mut DMatrix<f64>) {
        out.fill(0.0);
        for (xc, mut oc) in x.column_iter().zip(out.column_iter_mut()) {
            let xs = xc.as_slice();
            self.mul_add(1.0, xs, oc.as_mut_slice());
        }
    }

    /// Dense copy.
    pub fn to_dense(&self) -> DMatrix<f64> {
        let n = self.dim;
        let mut m = DMatrix::zeros(n, n);
        for j in 0..n {
            for d in 0..=self.bandwidth.min(n - 1 - j) {
                let v = self.data[j * (self.bandwidth + 1) + d];
                m[(j + d, j)] = v;
                m[(j, j + d)] = v;
            }
        }
        m
    }

    /// Band copy of a dense symmetric matrix (the lower triangle is read); the half-bandwidth is
    /// the smallest that holds every nonzero entry. O(n²).
    pub fn from_dense(a: &DMatrix<f64>) -> Self {
        let n = a.nrows();
        let mut b = 0;
        for j in 0..n {
            if let Some(last) = (j..n).rev().find(|&i| a[(i, j)] != 0.0) {
                b = b.max(last - j);
            }
        }
        let mut s = Self::zeros(n, b);
        for j in 0..n {
            for d in 0..=b.min(n - 1 - j) {
                s.data[j * (b + 1) + d] = a[(j + d, j)];
            }
        }
        s
    }

    /// Cholesky factor A = LLᵀ, or `None` when A is not (numerically) positive definite.
    pub fn cholesky(&self) -> Option<BandCholesky> {
        let (n, b) = (self.dim, self.bandwidth);
        let w = b + 1;
        let mut l = self.data.clone();
        for j in 0..n {
            // L[j, j] = sqrt(A[j, j] − Σₖ L[j, k]²), k = j − b … j − 1.
            let mut d = l[j * w];
            for k in j.saturating_sub(b)..j {
                let v = l[k * w + (j - k)];
                d -= v * v;
            }
            if !(d > 0.0 && d.is_finite()) {
                return None;
            }
            let djj = d.sqrt();
            l[j * w] = djj;
            // L[i, j] = (A[i, j] − Σₖ L[i, k] L[j, k]) / L[j, j], i = j + 1 … j + b.
            for i in j + 1..n.min(j + w) {
                let mut s = l[j * w + (i - j)];
                for k in i.saturating_sub(b)..j {
                    s -= l[k * w + (i - k)] * l[k * w + (j - k)];
                }
                l[j * w + (i - j)] = s / djj;
            }
        }
        Some(BandCholesky { dim: n, bandwidth: b, data: l })
    }
}

/// Cholesky factor L of a symmetric positive definite band matrix, same band layout.
#[derive(Debug, Clone, PartialEq)]
pub struct BandCholesky {
    dim: usize,
    bandwidth: usize,
    data: Vec<f64>,
}

impl BandCholesky {
    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Smallest and largest diagonal entry of L (its pivots): a tiny ratio reveals a nearly
    /// singular matrix.
    pub fn pivot_range(&self) -> (f64, f64) {
        let w = self.bandwidth + 1;
        (0..self.dim)
            .map(|j| self.data[j * w])
            .fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)))
    }

    /// Solves A x = b in place (b ← x): L y = b, then Lᵀ x = y. O(n·b).
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let (n, b) = (self.dim, self.bandwidth);
        let w = b + 1;
        let l = &self.data;
        debug_assert_eq!(x.len(), n);
        // Forward, column-oriented: x[j] /= L[j,j]; x[i] −= L[i,j] x[j].
        for j in 0..n {
            let col = &l[j * w..j * w + w.min(n - j)];
            let xj = x[j] / col[0];
            x[j] = xj;
            for (d, &a) in col.iter().enumerate().skip(1) {
                x[j + d] -= a * xj;
            }
        }
        // Backward, row-oriented on Lᵀ: x[j] = (x[j] − Σ L[i,j] x[i]) / L[j,j].
        for j in (0..n).rev() {
            let col = &l[j * w..j * w + w.min(n - j)];
            let mut s = x[j];
            for (d, &a) in col.iter().enumerate().skip(1) {
                s -= a * x[j + d];
            }
            x[j] = s / col[0];
        }
    }

    /// Solves A X = B for every column of `b` in place.
    pub fn solve_columns(&self, b: &mut DMatrix<f64>) {
        for mut c in b.column_iter_mut() {
            self.solve_in_place(c.as_mut_slice());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    fn sample(n: usize, b: usize) -> BandedSymmetric {
        let mut s = BandedSymmetric::zeros(n, b);
        for i in 0..n {
            s.add(i, i, 4.0 + i as f64 * 0.1);
            for d in 1..=b.min(n - 1 - i) {
                s.add(i + d, i, -0.5 / d as f64 + 0.01 * i as f64);
            }
        }
        s
    }

    #[test]
    fn product_and_dense_round_trip() {
        let s = sample(9, 3);
        let d = s.to_dense();
        assert_eq!(BandedSymmetric::from_dense(&d), s);
        let x = DVector::from_fn(9, |i, _| (i as f64 * 0.7).sin());
        let mut y = vec![0.0; 9];
        s.mul_add(2.0, x.as_slice(), &mut y);
        let want = &d * &x * 2.0;
        for i in 0..9 {
            assert!((y[i] - want[i]).abs() < 1e-14, "{i}");
        }
        assert_eq!(s.get(0, 3), d[(0, 3)]);
        assert_eq!(s.get(0, 4), 0.0);
        assert_eq!(s.widened(5).to_dense(), d);
        assert_eq!(s.add_scaled(2.0, &sample(9, 1)).to_dense(), &d + sample(9, 1).to_dense() * 2.0);
    }

    #[test]
    fn cholesky_solves_like_dense() {
        for (n, b) in [(1, 0), (5, 1), (12, 3), (7, 6)] {
            let s = sample(n, b);
            let chol = s.cholesky().expect("positive definite");
            let rhs = DVector::from_fn(n, |i, _| 1.0 + i as f64);
            let mut x = rhs.clone();
            chol.solve_in_place(x.as_mut_slice());
            let want = s.to_dense().cholesky().unwrap().solve(&rhs);
            assert!((&x - &want).amax() < 1e-13 * want.amax(), "n = {n}, b = {b}");
        }
        let mut neg = sample(4, 1);
        neg.add(2, 2, -10.0);
        assert!(neg.cholesky().is_none());
    }

    #[test]
    fn non_finite_entries_are_located() {
        let mut s = sample(5, 2);
        s.add(3, 1, f64::NAN);
        assert!(matches!(s.first_non_finite(), Some((3, 1, v)) if v.is_nan()));
        assert_eq!(sample(5, 2).first_non_finite(), None);
    }
}
