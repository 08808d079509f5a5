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

    /// Σᵢⱼ |Aᵢⱼ|·|xᵢ|·|xⱼ| (both triangles): how much the entries' own rounding can move xᵀAx.
    pub fn abs_quadratic(&self, x: &[f64]) -> f64 {
        let w = self.bandwidth + 1;
        let mut sum = 0.0;
        for j in 0..self.dim {
            for d in 0..w.min(self.dim - j) {
                let term = self.data[j * w + d].abs() * x[j + d].abs() * x[j].abs();
                sum += if d == 0 { term } else { 2.0 * term };
            }
        }
        sum
    }

    /// Computes `out += alpha · A x`.
    pub fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        debug_assert!(x.len() == self.dim && out.len() == self.dim);
        let w = self.bandwidth + 1;
        // Beam models (half-bandwidth 3) get a kernel of their own.
        match w {
            4 => mul_add_band_3(&self.data, alpha, x, out),
            _ => mul_add_band(&self.data, w, alpha, x, out),
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

    /// Where A stops being positive definite: the first j (from 0) whose leading
    /// (j + 1)×(j + 1) block, in this numbering, is not positive definite — the pivot at which
    /// its Cholesky factorisation fails; `None` when A is positive definite. O(n·b²).
    pub fn first_failed_pivot(&self) -> Option<usize> {
        let mut l = self.data.clone();
        band_cholesky(&mut l, self.dim, self.bandwidth).err()
    }

    /// Cholesky factor A = LLᵀ, or `None` when A is not (numerically) positive definite.
    pub fn cholesky(&self) -> Option<BandCholesky> {
        let mut f = BandCholesky::default();
        f.factor_shifted(self, 0.0, self).then_some(f)
    }

    /// A X for a row-major block X (n×p: row i is `x[i·p..(i + 1)·p]`) into `out` (overwritten).
    /// Working on whole rows keeps the p columns in the innermost, vectorisable loop.
    pub fn mul_block(&self, x: &[f64], out: &mut [f64], p: usize) {
        let (n, w) = (self.dim, self.bandwidth + 1);
        debug_assert!(x.len() == n * p && out.len() == n * p);
        out.fill(0.0);
        for j in 0..n {
            let col = &self.data[j * w..j * w + w.min(n - j)];
            let (head, tail) = out.split_at_mut((j + 1) * p);
            let oj = &mut head[j * p..];
            let xj = &x[j * p..(j + 1) * p];
            for (o, &v) in oj.iter_mut().zip(xj) {
                *o += col[0] * v;
            }
            for (d, &a) in col.iter().enumerate().skip(1) {
                let od = &mut tail[(d - 1) * p..d * p];
                let xd = &x[(j + d) * p..(j + d + 1) * p];
                for c in 0..p {
                    od[c] += a * xj[c];
                    oj[c] += a * xd[c];
                }
            }
        }
    }

    /// Number of eigenvalues of K φ = λ M φ below `sigma` (K = `self`, M = `mass` positive
    /// definite), by Sylvester's law of inertia: the negative pivots of K − σM = LDLᵀ. `None` when
    /// a pivot vanishes (σ is an eigenvalue to round-off). `scratch` is reused storage. O(n·b²).
    pub fn count_below(&self, mass: &BandedSymmetric, sigma: f64, scratch: &mut Vec<f64>) -> Option<usize> {
        let b = self.bandwidth.max(mass.bandwidth);
        self.shifted_into(-sigma, mass, b, scratch);
        band_ldlt(scratch, self.dim, b)
    }

    /// `self + sigma · other` in band storage of half-bandwidth `b` (≥ both) into `out`.
    fn shifted_into(&self, sigma: f64, other: &BandedSymmetric, b: usize, out: &mut Vec<f64>) {
        let (n, w) = (self.dim, b + 1);
        out.clear();
        out.resize(n * w, 0.0);
        for (j, col) in out.chunks_exact_mut(w).enumerate() {
            let len = (self.bandwidth + 1).min(n - j);
            col[..len].copy_from_slice(&self.data[j * (self.bandwidth + 1)..][..len]);
            if sigma != 0.0 {
                let len = (other.bandwidth + 1).min(n - j);
                for (c, &v) in col[..len].iter_mut().zip(&other.data[j * (other.bandwidth + 1)..][..len]) {
                    *c += sigma * v;
                }
            }
        }
    }
}

/// out += α·A x for the band array `a` of width w.
fn mul_add_band(a: &[f64], w: usize, alpha: f64, x: &[f64], out: &mut [f64]) {
    let n = x.len();
    for j in 0..n {
        let col = &a[j * w..j * w + w.min(n - j)];
        let xj = alpha * x[j];
        out[j] += col[0] * xj;
        let mut acc = 0.0;
        for (d, &c) in col.iter().enumerate().skip(1) {
            out[j + d] += c * xj;
            acc += c * x[j + d];
        }
        out[j] += alpha * acc;
    }
}

/// Solves L̃DL̃ᵀ x = b in place for the factor array `l` of width w: L̃ y = b, D z = y, L̃ᵀ x = z.
fn solve_band(l: &[f64], w: usize, inverse_diagonal: &[f64], x: &mut [f64]) {
    let n = x.len();
    for j in 0..n {
        let len = w.min(n - j);
        let xj = x[j];
        for (t, &a) in x[j + 1..j + len].iter_mut().zip(&l[j * w + 1..j * w + len]) {
            *t -= a * xj;
        }
    }
    for (v, &inv) in x.iter_mut().zip(inverse_diagonal) {
        *v *= inv;
    }
    for j in (0..n).rev() {
        let len = w.min(n - j);
        // Farthest term first: the nearest, x[j + 1], was computed last.
        let s: f64 = x[j + 1..j + len].iter().zip(&l[j * w + 1..j * w + len]).rev().map(|(t, a)| a * t).sum();
        x[j] -= s;
    }
}

/// [`mul_add_band`] for half-bandwidth 3 (beam models) by rows: each output entry is one sum
/// of seven independent products, with no store–reload chain between neighbouring rows.
fn mul_add_band_3(a: &[f64], alpha: f64, x: &[f64], out: &mut [f64]) {
    let n = x.len();
    let at = |i: usize| if i < n { x[i] } else { 0.0 };
    let edge = |j: usize| {
        let col = &a[4 * j..4 * j + 4];
        let mut s = col[0] * x[j] + col[1] * at(j + 1) + col[2] * at(j + 2) + col[3] * at(j + 3);
        for d in 1..=j.min(3) {
            s += a[4 * (j - d) + d] * x[j - d];
        }
        s
    };
    let inner = 3..n.saturating_sub(3).max(3);
    for j in (0..n).filter(|j| !inner.contains(j)) {
        out[j] += alpha * edge(j);
    }
    // Rows with the whole band inside the matrix: fixed windows, no branches.
    for j in inner {
        let (xw, aw) = (&x[j - 3..j + 4], &a[4 * (j - 3)..4 * j + 4]);
        let lower = aw[12] * xw[3] + aw[13] * xw[4] + aw[14] * xw[5] + aw[15] * xw[6];
        let upper = aw[9] * xw[2] + aw[6] * xw[1] + aw[3] * xw[0];
        out[j] += alpha * (lower + upper);
    }
}

/// [`solve_band`] for half-bandwidth 3 (beam models), n ≥ 4, with the three entries still being
/// updated held in registers: each row then costs one multiply–add on the dependency chain
/// instead of a store and reload through memory.
fn solve_band_3(l: &[f64], inverse_diagonal: &[f64], x: &mut [f64]) {
    let n = x.len();
    let (mut p0, mut p1, mut p2) = (x[0], x[1], x[2]);
    for j in 0..n {
        let col = &l[4 * j..4 * j + 4];
        let next = if j + 3 < n { x[j + 3] } else { 0.0 };
        x[j] = p0;
        // Padding entries past the matrix are zero, so the last rows need no special case.
        (p0, p1, p2) = (p1 - col[1] * p0, p2 - col[2] * p0, next - col[3] * p0);
    }
    for (v, &inv) in x.iter_mut().zip(inverse_diagonal) {
        *v *= inv;
    }
    let (mut q1, mut q2, mut q3) = (0.0, 0.0, 0.0);
    for j in (0..n).rev() {
        let col = &l[4 * j..4 * j + 4];
        let v = (x[j] - col[3] * q3 - col[2] * q2) - col[1] * q1;
        x[j] = v;
        (q1, q2, q3) = (v, q1, q2);
    }
}

/// In-place Cholesky factor L of a band array (layout of [`band_ldlt`]); false when the matrix
/// is not (numerically) positive definite. The same operations, in the same order, as the dense
/// solver's Cholesky (square roots, division by the pivot): on a stiff, finely meshed beam the
/// lowest eigenvalue depends on the factor's rounding — the LDLᵀ recurrence, or multiplying by
/// 1/L[j, j] instead of dividing, moved λ₁ of a 302-DOF shaft by 2e-9 — so identical arithmetic
/// is what keeps the backends agreeing there (to 3e-15); neither answer is more exact than 1e-9.
fn band_cholesky(l: &mut [f64], n: usize, b: usize) -> Result<(), usize> {
    let w = b + 1;
    for j in 0..n {
        // L[j, j] = sqrt(A[j, j] − Σₖ L[j, k]²), k = j − b … j − 1.
        let mut d = l[j * w];
        for k in j.saturating_sub(b)..j {
            let v = l[k * w + (j - k)];
            d -= v * v;
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(j);
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
    Ok(())
}

/// In-place LDLᵀ of a band array (column j at `a[j·w..]`, diagonal first, w = b + 1): on return
/// the unit L below the diagonal and D on it. The number of negative pivots, or `None` at a zero
/// or non-finite pivot. No pivoting: for the definite matrices and Sturm shifts it serves, the
/// pivots' signs are the inertia (Sylvester).
fn band_ldlt(a: &mut [f64], n: usize, b: usize) -> Option<usize> {
    let w = b + 1;
    let mut negative = 0;
    for j in 0..n {
        let mut dj = a[j * w];
        for k in j.saturating_sub(b)..j {
            let l = a[k * w + (j - k)];
            dj -= l * l * a[k * w];
        }
        if dj == 0.0 || !dj.is_finite() {
            return None;
        }
        a[j * w] = dj;
        negative += usize::from(dj < 0.0);
        let inv = 1.0 / dj;
        for i in j + 1..n.min(j + w) {
            let mut s = a[j * w + (i - j)];
            for k in i.saturating_sub(b)..j {
                s -= a[k * w + (i - k)] * a[k * w + (j - k)] * a[k * w];
            }
            a[j * w + (i - j)] = s * inv;
        }
    }
    Some(negative)
}

/// Factor of a symmetric positive definite band matrix A = LLᵀ, stored as A = L̃DL̃ᵀ (L̃ unit
/// lower, D = diag(L)²) in the same band layout: the solves then carry one multiply–add per
/// band entry on their dependency chain, no division.
///
/// Reusable: [`factor_shifted`](Self::factor_shifted) refactors into the same storage, so a
/// solver called in a loop does not allocate.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BandCholesky {
    dim: usize,
    bandwidth: usize,
    /// L̃ below the diagonal, D on it.
    data: Vec<f64>,
    /// 1 / Dⱼ.
    inverse_diagonal: Vec<f64>,
}

impl BandCholesky {
    /// Factors K + σM into this storage (the band is the wider of the two). False when the
    /// matrix is not (numerically) positive definite; the storage then holds no valid factor.
    pub fn factor_shifted(&mut self, k: &BandedSymmetric, sigma: f64, m: &BandedSymmetric) -> bool {
        assert_eq!(k.dim, m.dim, "band matrices of different size");
        let b = if sigma == 0.0 { k.bandwidth } else { k.bandwidth.max(m.bandwidth) };
        self.dim = k.dim;
        self.bandwidth = b;
        k.shifted_into(sigma, m, b, &mut self.data);
        if band_cholesky(&mut self.data, self.dim, b).is_err() {
            return false;
        }
        // L = L̃ D^½: scale each column by its pivot.
        let w = b + 1;
        self.inverse_diagonal.clear();
        for col in self.data.chunks_exact_mut(w) {
            let inv = 1.0 / col[0];
            for v in &mut col[1..] {
                *v *= inv;
            }
            col[0] *= col[0];
            self.inverse_diagonal.push(inv * inv);
        }
        true
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Smallest and largest diagonal entry of L (its pivots, √Dⱼ): a tiny ratio reveals a nearly
    /// singular matrix.
    pub fn pivot_range(&self) -> (f64, f64) {
        let (lo, hi) = self
            .data
            .iter()
            .step_by(self.bandwidth + 1)
            .fold((f64::INFINITY, 0.0_f64), |(a, b), &v| (a.min(v), b.max(v)));
        (lo.sqrt(), hi.sqrt())
    }

    /// Solves A x = b in place (b ← x): L̃ y = b, D z = y, L̃ᵀ x = z. O(n·b).
    pub fn solve_in_place(&self, x: &mut [f64]) {
        debug_assert_eq!(x.len(), self.dim);
        let (l, inv) = (&self.data, &self.inverse_diagonal);
        match self.bandwidth + 1 {
            4 if self.dim >= 4 => solve_band_3(l, inv, x),
            w => solve_band(l, w, inv, x),
        }
    }

    /// Solves A X = B in place for a row-major block B (n×p, as in
    /// [`BandedSymmetric::mul_block`]). O(n·b·p).
    pub fn solve_block(&self, x: &mut [f64], p: usize) {
        let (n, w) = (self.dim, self.bandwidth + 1);
        let l = &self.data;
        debug_assert_eq!(x.len(), n * p);
        for j in 0..n {
            let col = &l[j * w..j * w + w.min(n - j)];
            let (head, tail) = x.split_at_mut((j + 1) * p);
            let xj = &head[j * p..];
            for (d, &a) in col.iter().enumerate().skip(1) {
                for (t, &v) in tail[(d - 1) * p..d * p].iter_mut().zip(xj) {
                    *t -= a * v;
                }
            }
        }
        for (row, &inv) in x.chunks_exact_mut(p).zip(&self.inverse_diagonal) {
            row.iter_mut().for_each(|v| *v *= inv);
        }
        for j in (0..n).rev() {
            let col = &l[j * w..j * w + w.min(n - j)];
            let (head, tail) = x.split_at_mut((j + 1) * p);
            let xj = &mut head[j * p..];
            for (d, &a) in col.iter().enumerate().skip(1) {
                for (v, &t) in xj.iter_mut().zip(&tail[(d - 1) * p..d * p]) {
                    *v -= a * t;
                }
            }
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
