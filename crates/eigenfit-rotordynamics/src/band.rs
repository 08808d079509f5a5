//! General (non-symmetric) band matrices — how a rotor's M, C + ΩG and K are held at speed: each
//! node couples to its neighbours only, so every nonzero lies within a few places of the
//! diagonal — and their LU factors with partial pivoting (LAPACK's dgbtrf scheme).
//!
//! Own band LU because faer's sparse LU needs its heavy `sparse-linalg` feature and the band
//! here is narrow (7 either side for a shaft) and known before any number is assembled.

use eigenfit_core::matrix::BandedSymmetric;
use faer::{c64, Mat};

/// Something a rotor's matrices are assembled into: a dense matrix or a [`Band`].
pub trait Assemble {
    /// Adds `value` at (i, j).
    fn add(&mut self, i: usize, j: usize, value: f64);
}

impl Assemble for Mat<f64> {
    fn add(&mut self, i: usize, j: usize, value: f64) {
        self[(i, j)] += value;
    }
}

/// An n×n matrix whose nonzeros lie at most `lower` places below and `upper` above the diagonal.
///
/// Stored by rows: entry (i, j) lives at `data[i·w + (j + lower − i)]`, w = lower + upper + 1
/// (places before column 0 or past column n − 1 are padding, kept at zero).
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    n: usize,
    lower: usize,
    upper: usize,
    data: Vec<f64>,
}

impl Band {
    /// An all-zero n×n band matrix.
    pub fn zeros(n: usize, lower: usize, upper: usize) -> Self {
        Band { n, lower, upper, data: vec![0.0; n * (lower + upper + 1)] }
    }

    /// The band of a dense matrix, as narrow as its nonzeros allow.
    pub fn from_dense(a: &Mat<f64>) -> Self {
        let n = a.nrows();
        let (mut lower, mut upper) = (0, 0);
        for j in 0..n {
            for i in 0..n {
                if a[(i, j)] != 0.0 {
                    if i > j {
                        lower = lower.max(i - j);
                    } else {
                        upper = upper.max(j - i);
                    }
                }
            }
        }
        let mut b = Band::zeros(n, lower, upper);
        let w = b.width();
        for i in 0..n {
            for j in i.saturating_sub(lower)..(i + upper + 1).min(n) {
                b.data[i * w + j + lower - i] = a[(i, j)];
            }
        }
        b
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// How far below the diagonal nonzeros may lie.
    pub fn lower(&self) -> usize {
        self.lower
    }

    /// How far above the diagonal nonzeros may lie.
    pub fn upper(&self) -> usize {
        self.upper
    }

    fn width(&self) -> usize {
        self.lower + self.upper + 1
    }

    /// The columns of row i inside the matrix, and where the first sits in `data`.
    #[inline]
    fn row(&self, i: usize) -> (std::ops::Range<usize>, usize) {
        let first = i.saturating_sub(self.lower);
        let end = (i + self.upper + 1).min(self.n);
        (first..end, i * self.width() + first + self.lower - i)
    }

    /// Entry (i, j); zero outside the band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i + self.upper < j || j + self.lower < i || i >= self.n || j >= self.n {
            0.0
        } else {
            self.data[i * self.width() + j + self.lower - i]
        }
    }

    /// The dense matrix.
    pub fn to_dense(&self) -> Mat<f64> {
        let mut a = Mat::zeros(self.n, self.n);
        for i in 0..self.n {
            let (cols, at) = self.row(i);
            for (c, j) in cols.enumerate() {
                a[(i, j)] = self.data[at + c];
            }
        }
        a
    }

    /// `self += alpha · other`, both of the same shape and band.
    ///
    /// # Panics
    /// When the shapes differ: a bug in the caller.
    pub fn add_scaled(&mut self, alpha: f64, other: &Band) {
        assert!(
            (self.n, self.lower, self.upper) == (other.n, other.lower, other.upper),
            "band shapes differ"
        );
        self.data.iter_mut().zip(&other.data).for_each(|(a, b)| *a += alpha * b);
    }

    /// out += α·A x.
    pub fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            let (cols, at) = self.row(i);
            let s: f64 = self.data[at..at + cols.len()].iter().zip(&x[cols]).map(|(a, b)| a * b).sum();
            *o += alpha * s;
        }
    }

    /// out += α·A x + α·B y in one pass over the rows, the same sums in the same order as
    /// `A.mul_add(α, x, out)` then `B.mul_add(α, y, out)` (so the same result to the bit), but
    /// the two row sums interleave: each is a chain of dependent additions, and two chains in
    /// flight take about the time of one (the shift-invert operator applies M and C + ΩG
    /// together at every Krylov step).
    pub fn mul_add_pair(a: &Band, x: &[f64], b: &Band, y: &[f64], alpha: f64, out: &mut [f64]) {
        if (a.n, a.lower, a.upper) != (b.n, b.lower, b.upper) {
            a.mul_add(alpha, x, out);
            b.mul_add(alpha, y, out);
            return;
        }
        for (i, o) in out.iter_mut().enumerate().take(a.n) {
            let (cols, at) = a.row(i);
            let len = cols.len();
            let (ra, rb) = (&a.data[at..at + len], &b.data[at..at + len]);
            let (xs, ys) = (&x[cols.clone()], &y[cols]);
            let (mut sa, mut sb) = (0.0, 0.0);
            for c in 0..len {
                sa += ra[c] * xs[c];
                sb += rb[c] * ys[c];
            }
            *o += alpha * sa;
            *o += alpha * sb;
        }
    }

    /// The quadratic form xᴴ A x of a complex vector.
    pub fn quadratic_form(&self, x: &[c64]) -> c64 {
        let mut total = c64::new(0.0, 0.0);
        for (i, xi) in x.iter().enumerate().take(self.n) {
            let (cols, at) = self.row(i);
            let mut row = c64::new(0.0, 0.0);
            for (a, xj) in self.data[at..at + cols.len()].iter().zip(&x[cols]) {
                row += xj * *a;
            }
            total += xi.conj() * row;
        }
        total
    }

    /// The largest absolute row sum ‖A‖∞.
    pub fn norm_inf(&self) -> f64 {
        (0..self.n)
            .map(|i| {
                let (cols, at) = self.row(i);
                self.data[at..at + cols.len()].iter().map(|v| v.abs()).sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// The transpose.
    pub fn transpose(&self) -> Band {
        let mut t = Band::zeros(self.n, self.upper, self.lower);
        for i in 0..self.n {
            let (cols, at) = self.row(i);
            for (c, j) in cols.enumerate() {
                t.add(j, i, self.data[at + c]);
            }
        }
        t
    }

    /// The symmetric part (A + Aᵀ)/2, in core's symmetric band storage.
    pub fn symmetric_part(&self) -> BandedSymmetric {
        let mut s = BandedSymmetric::zeros(self.n, self.lower.max(self.upper));
        for i in 0..self.n {
            let (cols, at) = self.row(i);
            for (c, j) in cols.enumerate() {
                // (i, j) and (j, i) each add half to the one stored entry.
                let v = self.data[at + c];
                if j <= i && v != 0.0 {
                    s.add(i, j, if i == j { v } else { 0.5 * v });
                } else if v != 0.0 {
                    s.add(j, i, 0.5 * v);
                }
            }
        }
        s
    }
}

impl Assemble for Band {
    /// # Panics
    /// When (i, j) lies outside the band: the band was sized wrongly (a bug, not user input).
    fn add(&mut self, i: usize, j: usize, value: f64) {
        assert!(
            i < self.n && j < self.n && j + self.lower >= i && i + self.upper >= j,
            "entry ({i}, {j}) outside the {0}×{0} band ({1} below, {2} above)",
            self.n,
            self.lower,
            self.upper
        );
        let w = self.width();
        self.data[i * w + j + self.lower - i] += value;
    }
}

/// LU factors of a [`Band`] with partial pivoting: U's upper bandwidth grows to upper + lower.
#[derive(Debug, Clone)]
pub struct BandLu {
    n: usize,
    kl: usize,
    /// Upper bandwidth of U after pivoting: ku + kl.
    ku2: usize,
    w: usize,
    band: Vec<f64>,
    piv: Vec<usize>,
}

impl BandLu {
    /// Factors `a`. `None` when a pivot vanishes (below 1e-14 of the largest entry: singular).
    pub fn new(a: &Band) -> Option<Self> {
        let (n, kl, ku) = (a.n, a.lower, a.upper);
        let ku2 = ku + kl;
        let w = kl + ku2 + 1;
        let mut band = vec![0.0; n * w];
        let idx = |i: usize, j: usize| i * w + (j + kl - i);
        for i in 0..n {
            let (cols, at) = a.row(i);
            let start = idx(i, cols.start);
            band[start..start + cols.len()].copy_from_slice(&a.data[at..at + cols.len()]);
        }
        let scale = band.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut piv = vec![0; n];
        for k in 0..n {
            let last_row = (k + kl + 1).min(n);
            let last_col = (k + ku2 + 1).min(n);
            let mut p = k;
            for i in k + 1..last_row {
                if band[idx(i, k)].abs() > band[idx(p, k)].abs() {
                    p = i;
                }
            }
            piv[k] = p;
            if band[idx(p, k)].abs() <= 1e-14 * scale {
                return None;
            }
            if p != k {
                for j in k..last_col {
                    band.swap(idx(k, j), idx(p, j));
                }
            }
            let d = band[idx(k, k)];
            for i in k + 1..last_row {
                let l = band[idx(i, k)] / d;
                band[idx(i, k)] = l;
                if l != 0.0 {
                    let (top, bottom) = band.split_at_mut(idx(i, k + 1));
                    let pivot_row = &top[idx(k, k + 1)..idx(k, last_col)];
                    bottom[..last_col - k - 1].iter_mut().zip(pivot_row).for_each(|(x, p)| *x -= l * p);
                }
            }
        }
        Some(BandLu { n, kl, ku2, w, band, piv })
    }

    /// Solves A x = b in place.
    // `b` and the band are indexed together (row i of the band holds b[i]'s coefficients).
    #[allow(clippy::needless_range_loop)]
    pub fn solve(&self, b: &mut [f64]) {
        let (n, kl, w) = (self.n, self.kl, self.w);
        let idx = |i: usize, j: usize| i * w + (j + kl - i);
        for k in 0..n {
            b.swap(k, self.piv[k]);
            let bk = b[k];
            if bk != 0.0 {
                for i in k + 1..(k + kl + 1).min(n) {
                    b[i] -= self.band[idx(i, k)] * bk;
                }
            }
        }
        for i in (0..n).rev() {
            let end = (i + self.ku2 + 1).min(n);
            let row = &self.band[idx(i, i + 1)..idx(i, end)];
            let s: f64 = row.iter().zip(&b[i + 1..end]).map(|(a, x)| a * x).sum();
            b[i] = (b[i] - s) / self.band[idx(i, i)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(n: usize, lower: usize, upper: usize) -> Mat<f64> {
        Mat::from_fn(n, n, |i, j| {
            if j + lower >= i && i + upper >= j {
                ((i * 7 + j * 3) % 11) as f64 - 4.5 + if i == j { 0.3 } else { 0.0 }
            } else {
                0.0
            }
        })
    }

    #[test]
    fn band_products_and_solves_match_the_dense_matrix() {
        let a = sample(23, 3, 5);
        let b = Band::from_dense(&a);
        assert_eq!((b.lower(), b.upper()), (3, 5));
        assert_eq!(b.to_dense(), a);
        let x: Vec<f64> = (0..23).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; 23];
        b.mul_add(1.0, &x, &mut y);
        for i in 0..23 {
            let dense: f64 = (0..23).map(|j| a[(i, j)] * x[j]).sum();
            assert!((y[i] - dense).abs() < 1e-12 * (1.0 + dense.abs()));
        }
        // The fused pair gives the two products' sum to the bit.
        let c = Band::from_dense(&Mat::from_fn(23, 23, |i, j| {
            if j + 3 >= i && i + 5 >= j {
                (i as f64 - 2.0 * j as f64).sin()
            } else {
                0.0
            }
        }));
        assert_eq!((c.lower(), c.upper()), (3, 5));
        let x2: Vec<f64> = (0..23).map(|i| (i as f64 * 1.3).cos()).collect();
        let (mut two, mut fused) = (vec![0.5; 23], vec![0.5; 23]);
        b.mul_add(-1.0, &x, &mut two);
        c.mul_add(-1.0, &x2, &mut two);
        Band::mul_add_pair(&b, &x, &c, &x2, -1.0, &mut fused);
        assert_eq!(two, fused);
        let lu = BandLu::new(&b).unwrap();
        let mut z = y.clone();
        lu.solve(&mut z);
        for i in 0..23 {
            assert!((z[i] - x[i]).abs() < 1e-9, "{i}: {} vs {}", z[i], x[i]);
        }
        assert_eq!(b.transpose().to_dense(), a.transpose().to_owned());
        let s = b.symmetric_part();
        for i in 0..23 {
            for j in 0..23 {
                assert!((s.get(i, j) - 0.5 * (a[(i, j)] + a[(j, i)])).abs() < 1e-15);
            }
        }
    }
}
