//! The lowest modes of a large rotor without the dense 2n eigen-solve: Arnoldi on the
//! shift-inverted state-space operator (A − σI)⁻¹, applied through a banded LU of the n×n
//! quadratic matrix K + σD + σ²M (a rotor's matrices are banded: each node couples to its
//! neighbours only). The eigenvalues nearest σ = 0 converge first; they are the low modes.
//!
//! Own banded LU (LAPACK's dgbtrf scheme) because faer's sparse LU needs its heavy
//! `sparse-linalg` feature and the band here is narrow (about 8) and known.

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{evd_real, evd_scratch, ComputeEigenvectors};
use faer::{c64, Mat, MatRef, Par};

/// LU factors of a banded matrix with partial pivoting (band storage, LAPACK layout in spirit).
struct BandLu {
    n: usize,
    kl: usize,
    /// Upper bandwidth of U after pivoting: ku + kl.
    ku2: usize,
    w: usize,
    band: Vec<f64>,
    piv: Vec<usize>,
}

impl BandLu {
    /// Factors the n×n matrix `a` whose nonzeros lie within `kl` below and `ku` above the
    /// diagonal. Returns `None` when a pivot vanishes (singular matrix).
    fn new(a: &Mat<f64>, kl: usize, ku: usize) -> Option<Self> {
        let n = a.nrows();
        let ku2 = ku + kl;
        let w = kl + ku2 + 1;
        let mut band = vec![0.0; n * w];
        let idx = |i: usize, j: usize| i * w + (j + kl - i);
        for i in 0..n {
            for j in i.saturating_sub(kl)..(i + ku + 1).min(n) {
                band[idx(i, j)] = a[(i, j)];
            }
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
                    for j in k + 1..last_col {
                        band[idx(i, j)] -= l * band[idx(k, j)];
                    }
                }
            }
        }
        Some(BandLu { n, kl, ku2, w, band, piv })
    }

    // `b` and the band are indexed together (row i of the band holds b[i]'s coefficients).
    #[allow(clippy::needless_range_loop)]
    fn solve(&self, b: &mut [f64]) {
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
            let mut s = b[i];
            for j in i + 1..(i + self.ku2 + 1).min(n) {
                s -= self.band[idx(i, j)] * b[j];
            }
            b[i] = s / self.band[idx(i, i)];
        }
    }
}

/// Lower and upper bandwidths of the nonzeros of some matrices.
fn bandwidths(mats: &[MatRef<'_, f64>]) -> (usize, usize) {
    let (mut kl, mut ku) = (0, 0);
    for a in mats {
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                if a[(i, j)] != 0.0 {
                    if i > j {
                        kl = kl.max(i - j);
                    } else {
                        ku = ku.max(j - i);
                    }
                }
            }
        }
    }
    (kl, ku)
}

/// Eigenpairs (λ, right state-vector's displacement part) of (λ²M + λD + K)x = 0 nearest 0:
/// at least `wanted` eigenvalues (counting each conjugate separately), all with Arnoldi
/// residual below 1e-10 relative. `None` when the band LU fails (K singular: a free rotor) or
/// the Krylov space would exceed the problem; the caller then solves densely.
pub fn nearest_zero(m: &Mat<f64>, d: &Mat<f64>, k: &Mat<f64>, wanted: usize) -> Option<Vec<(c64, Vec<c64>)>> {
    let n = m.nrows();
    let (kl, ku) = bandwidths(&[m.as_ref(), d.as_ref(), k.as_ref()]);
    // A band wider than a quarter of the matrix gains nothing over the dense solve.
    if 4 * (kl + ku) > n {
        return None;
    }
    let lu = BandLu::new(k, kl, ku)?;
    let mut dim = (2 * wanted + 20).max(40);
    loop {
        if dim + 1 >= 2 * n {
            return None;
        }
        if let Some(found) = arnoldi(&lu, m, d, n, dim, wanted) {
            return Some(found);
        }
        dim *= 2;
    }
}

fn matvec(a: &Mat<f64>, x: &[f64], out: &mut [f64], kl: usize, ku: usize) {
    let n = a.nrows();
    for i in 0..n {
        let mut s = 0.0;
        for j in i.saturating_sub(kl)..(i + ku + 1).min(n) {
            s += a[(i, j)] * x[j];
        }
        out[i] = s;
    }
}

fn arnoldi(
    lu: &BandLu,
    m: &Mat<f64>,
    d: &Mat<f64>,
    n: usize,
    dim: usize,
    wanted: usize,
) -> Option<Vec<(c64, Vec<c64>)>> {
    let (kl, ku) = (lu.kl, lu.ku2 - lu.kl);
    let size = 2 * n;
    // Op u = A⁻¹u: x2 = u1, K x1 = −M u2 − D u1.
    let op = |u: &[f64], out: &mut [f64]| {
        let (u1, u2) = u.split_at(n);
        let mut t = vec![0.0; n];
        let mut rhs = vec![0.0; n];
        matvec(m, u2, &mut t, kl, ku);
        matvec(d, u1, &mut rhs, kl, ku);
        for i in 0..n {
            rhs[i] = -t[i] - rhs[i];
        }
        lu.solve(&mut rhs);
        out[..n].copy_from_slice(&rhs);
        out[n..].copy_from_slice(u1);
    };
    let mut v: Vec<Vec<f64>> = Vec::with_capacity(dim + 1);
    // A fixed, generic start vector: results do not depend on a random seed.
    let mut v0: Vec<f64> = (0..size).map(|i| 1.0 + 0.5 * ((i as f64) * 0.73).sin()).collect();
    let nrm = v0.iter().map(|x| x * x).sum::<f64>().sqrt();
    v0.iter_mut().for_each(|x| *x /= nrm);
    v.push(v0);
    let mut h = Mat::<f64>::zeros(dim + 1, dim);
    let mut w = vec![0.0; size];
    let mut steps = dim;
    for j in 0..dim {
        op(&v[j], &mut w);
        // Two passes of Gram–Schmidt keep the basis orthogonal to working precision.
        for _ in 0..2 {
            for (i, vi) in v.iter().enumerate() {
                let c: f64 = vi.iter().zip(&w).map(|(a, b)| a * b).sum();
                h[(i, j)] += c;
                w.iter_mut().zip(vi).for_each(|(x, y)| *x -= c * y);
            }
        }
        let beta = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        h[(j + 1, j)] = beta;
        if beta < 1e-300 {
            steps = j + 1;
            break;
        }
        v.push(w.iter().map(|x| x / beta).collect());
    }
    let hm = h.as_ref().submatrix(0, 0, steps, steps).to_owned();
    let beta_last = h[(steps, steps - 1)];
    let mut ur = Mat::<f64>::zeros(steps, steps);
    let mut s_re = Diag::<f64>::zeros(steps);
    let mut s_im = Diag::<f64>::zeros(steps);
    let mut mem = MemBuffer::new(evd_scratch::<f64>(
        steps,
        ComputeEigenvectors::No,
        ComputeEigenvectors::Yes,
        Par::Seq,
        Default::default(),
    ));
    evd_real(
        hm.as_ref(),
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        Some(ur.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let (s_re, s_im) = (s_re.column_vector(), s_im.column_vector());
    // The wanted eigenvalues are the largest |θ| (nearest λ = 0); each must have converged:
    // residual |β sₘ|/‖s‖ ≤ 1e-10 |θ|.
    let mut order: Vec<usize> = (0..steps).collect();
    order.sort_by(|&a, &b| {
        let ta = c64::new(s_re[a], s_im[a]).norm();
        let tb = c64::new(s_re[b], s_im[b]).norm();
        tb.total_cmp(&ta)
    });
    let mut out = Vec::new();
    for &idx in order.iter().take(wanted.min(steps)) {
        let theta = c64::new(s_re[idx], s_im[idx]);
        let complex_first =
            s_im[idx] != 0.0 && idx + 1 < steps && s_im[idx] > 0.0 && s_im[idx + 1] == -s_im[idx];
        let complex_second = s_im[idx] != 0.0 && idx > 0 && s_im[idx - 1] == -s_im[idx] && s_im[idx] < 0.0;
        let s: Vec<c64> = (0..steps)
            .map(|i| {
                if complex_first {
                    c64::new(ur[(i, idx)], ur[(i, idx + 1)])
                } else if complex_second {
                    c64::new(ur[(i, idx - 1)], -ur[(i, idx)])
                } else {
                    c64::new(ur[(i, idx)], 0.0)
                }
            })
            .collect();
        let snorm = s.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        if beta_last * s[steps - 1].norm() / snorm > 1e-10 * theta.norm() {
            return None;
        }
        // Ritz vector's displacement half: x = V[..n] s.
        let mut x = vec![c64::new(0.0, 0.0); n];
        for (i, vi) in v.iter().take(steps).enumerate() {
            for r in 0..n {
                x[r] += s[i] * vi[r];
            }
        }
        out.push((theta.inv(), x));
    }
    Some(out)
}
