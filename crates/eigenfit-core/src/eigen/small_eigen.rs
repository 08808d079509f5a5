//! Eigen-decompositions of small symmetric matrices in caller-owned storage, for the iterative
//! solvers of [`BandedSolver`](crate::eigen::BandedSolver): cyclic Jacobi for the p×p Rayleigh–Ritz
//! matrices of subspace iteration (nearly diagonal after the first iteration: one or two sweeps),
//! implicit QL for the tridiagonal matrices of Lanczos. Neither allocates.

/// Sweeps allowed before giving up (quadratic convergence needs ~6–10 even from dense input).
const MAX_SWEEPS: usize = 50;

/// Eigen-decomposes the symmetric p×p matrix `a` (row-major, overwritten): on return its
/// diagonal holds the eigenvalues and `v` (row-major p×p) the eigenvectors as columns.
///
/// A rotation is skipped when |aᵢⱼ| ≤ ε·√(|aᵢᵢ aⱼⱼ|): stopping relative to the diagonal keeps
/// the small eigenvalues of a graded positive definite matrix accurate relative to themselves
/// (Demmel & Veselić 1992). Returns false if the sweeps run out (NaN input).
pub(crate) fn symmetric_eigen(a: &mut [f64], v: &mut [f64], p: usize) -> bool {
    debug_assert!(a.len() == p * p && v.len() == p * p);
    v.fill(0.0);
    for i in 0..p {
        v[i * p + i] = 1.0;
    }
    for _ in 0..MAX_SWEEPS {
        let mut rotated = false;
        for i in 0..p {
            for j in i + 1..p {
                let aij = a[i * p + j];
                let (aii, ajj) = (a[i * p + i], a[j * p + j]);
                if aij.abs() <= f64::EPSILON * (aii * ajj).abs().sqrt() {
                    continue;
                }
                if !aij.is_finite() {
                    return false;
                }
                rotated = true;
                rotate(a, v, p, i, j);
            }
        }
        if !rotated {
            return true;
        }
    }
    false
}

/// One Jacobi rotation annihilating a[i, j] (Rutishauser's stable formulas).
fn rotate(a: &mut [f64], v: &mut [f64], p: usize, i: usize, j: usize) {
    let aij = a[i * p + j];
    let theta = (a[j * p + j] - a[i * p + i]) / (2.0 * aij);
    let t = if theta.abs() > 1e150 {
        0.5 / theta
    } else {
        theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
    };
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    let tau = s / (1.0 + c);
    a[i * p + i] -= t * aij;
    a[j * p + j] += t * aij;
    a[i * p + j] = 0.0;
    a[j * p + i] = 0.0;
    for r in (0..p).filter(|&r| r != i && r != j) {
        let (g, h) = (a[r * p + i], a[r * p + j]);
        let gi = g - s * (h + g * tau);
        let hj = h + s * (g - h * tau);
        a[r * p + i] = gi;
        a[i * p + r] = gi;
        a[r * p + j] = hj;
        a[j * p + r] = hj;
    }
    for r in 0..p {
        let (g, h) = (v[r * p + i], v[r * p + j]);
        v[r * p + i] = g - s * (h + g * tau);
        v[r * p + j] = h + s * (g - h * tau);
    }
}

/// Eigenvalues of the symmetric tridiagonal matrix with diagonal `d` and off-diagonal `e`
/// (`e[i]` couples i and i + 1; `e[n − 1]` is workspace) by QL with implicit Wilkinson shifts
/// (EISPACK tql2). On return `d` holds the eigenvalues, unsorted, and `z` (n×n, column-major,
/// overwritten) the eigenvectors as columns. False if QL does not converge.
pub(crate) fn tridiagonal_eigen(d: &mut [f64], e: &mut [f64], z: &mut [f64]) -> bool {
    let n = d.len();
    debug_assert!(e.len() == n && z.len() == n * n);
    if n == 0 {
        return true;
    }
    z.fill(0.0);
    for i in 0..n {
        z[i * n + i] = 1.0;
    }
    e[n - 1] = 0.0;
    for l in 0..n {
        let mut iterations = 0;
        loop {
            let mut m = l;
            while m + 1 < n {
                let dd = d[m].abs() + d[m + 1].abs();
                if e[m].abs() <= f64::EPSILON * dd {
                    break;
                }
                m += 1;
            }
            if m == l {
                break;
            }
            iterations += 1;
            if iterations > 60 || !d[l].is_finite() || !e[l].is_finite() {
                return false;
            }
            let mut g = (d[l + 1] - d[l]) / (2.0 * e[l]);
            let mut r = if g.abs() > 1e150 { g.abs() } else { (g * g + 1.0).sqrt() };
            g = d[m] - d[l] + e[l] / (g + r.copysign(g));
            let (mut s, mut c, mut p) = (1.0_f64, 1.0_f64, 0.0_f64);
            let mut i = m;
            let mut deflated = false;
            while i > l {
                i -= 1;
                let f = s * e[i];
                let b = c * e[i];
                r = (f * f + g * g).sqrt();
                e[i + 1] = r;
                if r == 0.0 {
                    // Underflow: the matrix split at i + 1; restart this eigenvalue.
                    d[i + 1] -= p;
                    e[m] = 0.0;
                    deflated = true;
                    break;
                }
                let inv = 1.0 / r;
                s = f * inv;
                c = g * inv;
                g = d[i + 1] - p;
                r = (d[i] - g) * s + 2.0 * c * b;
                p = s * r;
                d[i + 1] = g + p;
                g = c * r - b;
                let (zi, zi1) = z[i * n..(i + 2) * n].split_at_mut(n);
                for (a, b) in zi.iter_mut().zip(zi1) {
                    let f = *b;
                    *b = s * *a + c * f;
                    *a = c * *a - s * f;
                }
            }
            if deflated {
                continue;
            }
            d[l] -= p;
            e[l] = g;
            e[m] = 0.0;
        }
    }
    true
}

/// The `count` largest eigenpairs of the symmetric tridiagonal matrix with diagonal `d` and
/// off-diagonal `e` (`e[i]` couples i and i + 1; entries from n − 1 on are ignored): values
/// descending into `values`, unit eigenvectors into `vectors` (count × n, each contiguous).
///
/// Rayleigh quotient iteration from deflated power-iteration starts — O(n) per iteration where QL
/// costs O(n²) rotations, each a square root and a division on one dependency chain — and every
/// pair certified by a Sturm count: exactly k eigenvalues above the k-th found (to round-off).
/// False when a certificate fails or an iteration does not settle (close eigenvalues, a poor
/// start): the caller then uses [`tridiagonal_eigen`]. `work` is reused storage.
pub(crate) fn tridiagonal_top(
    d: &[f64],
    e: &[f64],
    count: usize,
    values: &mut Vec<f64>,
    vectors: &mut Vec<f64>,
    work: &mut Vec<f64>,
) -> bool {
    let n = d.len();
    values.clear();
    vectors.clear();
    if count > n {
        return false;
    }
    vectors.resize(count * n, 0.0);
    work.clear();
    work.resize(3 * n, 0.0);
    let off = |i: usize| if i + 1 < n { e[i] } else { 0.0 };
    let norm = (0..n)
        .fold(0.0_f64, |m, i| m.max(d[i].abs() + off(i).abs() + if i > 0 { off(i - 1).abs() } else { 0.0 }));
    if !(norm > 0.0 && norm.is_finite()) {
        return false;
    }
    let tiny = f64::EPSILON * norm;
    for k in 0..count {
        let (found, rest) = vectors.split_at_mut(k * n);
        let s = &mut rest[..n];
        for (i, v) in s.iter_mut().enumerate() {
            *v = 1.0 + 0.1 * i as f64;
        }
        let (x, piv_l) = work.split_at_mut(n);
        // Power steps towards the largest remaining eigenvalue (T is positive definite here).
        for _ in 0..POWER_STEPS {
            tridiagonal_mul(d, e, s, x);
            s.copy_from_slice(x);
            if !deflate_normalise(s, found) {
                return false;
            }
        }
        let mut rho = rayleigh(d, e, s);
        let mut settled = false;
        for _ in 0..RQI_STEPS {
            if shifted_solve(d, e, rho, tiny, s, x, piv_l).is_none() {
                return false;
            }
            s.copy_from_slice(x);
            if !deflate_normalise(s, found) {
                return false;
            }
            rho = rayleigh(d, e, s);
            tridiagonal_mul(d, e, s, x);
            let residual = x.iter().zip(s.iter()).fold(0.0_f64, |m, (a, b)| m.max((a - rho * b).abs()));
            if residual <= 8.0 * tiny {
                settled = true;
                break;
            }
        }
        // Certificate: exactly k + 1 eigenvalues at or above this one (less its round-off).
        let below = match count_below(d, e, rho - 64.0 * tiny - 1e-10 * rho.abs(), tiny) {
            Some(c) => c,
            None => return false,
        };
        if !settled || n - below != k + 1 || values.last().is_some_and(|&v| rho >= v) {
            return false;
        }
        values.push(rho);
    }
    true
}

/// Power-iteration steps before the Rayleigh quotient iteration of [`tridiagonal_top`].
const POWER_STEPS: usize = 3;
/// Rayleigh quotient iterations allowed per pair (cubic convergence: 2–3 suffice).
const RQI_STEPS: usize = 8;

/// out = T s for the tridiagonal (d, e).
fn tridiagonal_mul(d: &[f64], e: &[f64], s: &[f64], out: &mut [f64]) {
    let n = d.len();
    for i in 0..n {
        let mut v = d[i] * s[i];
        if i > 0 {
            v += e[i - 1] * s[i - 1];
        }
        if i + 1 < n {
            v += e[i] * s[i + 1];
        }
        out[i] = v;
    }
}

/// sᵀ T s.
fn rayleigh(d: &[f64], e: &[f64], s: &[f64]) -> f64 {
    let n = d.len();
    let diag: f64 = d.iter().zip(s).map(|(a, b)| a * b * b).sum();
    let offd: f64 = (0..n.saturating_sub(1)).map(|i| e[i] * s[i] * s[i + 1]).sum();
    diag + 2.0 * offd
}

/// Removes the components along the unit vectors in `found` (each `s.len()` long) and
/// normalises; false for a vanishing or non-finite vector.
fn deflate_normalise(s: &mut [f64], found: &[f64]) -> bool {
    let n = s.len();
    for v in found.chunks_exact(n) {
        let c: f64 = v.iter().zip(s.iter()).map(|(a, b)| a * b).sum();
        s.iter_mut().zip(v).for_each(|(a, b)| *a -= c * b);
    }
    let norm = s.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return false;
    }
    s.iter_mut().for_each(|v| *v /= norm);
    true
}

/// Solves (T − ρI) x = s by LDLᵀ without pivoting, pivots below `tiny` raised to it (inverse
/// iteration only needs the direction, which a near-singular factor amplifies).
fn shifted_solve(
    d: &[f64],
    e: &[f64],
    rho: f64,
    tiny: f64,
    s: &[f64],
    x: &mut [f64],
    work: &mut [f64],
) -> Option<()> {
    let n = d.len();
    let (piv, l) = work.split_at_mut(n);
    let guard = |p: f64| if p.abs() < tiny { tiny.copysign(p) } else { p };
    piv[0] = guard(d[0] - rho);
    for i in 1..n {
        l[i - 1] = e[i - 1] / piv[i - 1];
        piv[i] = guard(d[i] - rho - l[i - 1] * e[i - 1]);
    }
    x[0] = s[0];
    for i in 1..n {
        x[i] = s[i] - l[i - 1] * x[i - 1];
    }
    for i in 0..n {
        x[i] /= piv[i];
    }
    for i in (0..n.saturating_sub(1)).rev() {
        x[i] -= l[i] * x[i + 1];
    }
    x.iter().all(|v| v.is_finite()).then_some(())
}

/// Number of eigenvalues of the tridiagonal (d, e) below `sigma` (Sturm sequence), `None` for
/// non-finite input.
fn count_below(d: &[f64], e: &[f64], sigma: f64, tiny: f64) -> Option<usize> {
    let mut q = d[0] - sigma;
    let mut below = usize::from(q < 0.0);
    for i in 1..d.len() {
        if q == 0.0 {
            q = tiny;
        }
        q = d[i] - sigma - e[i - 1] * e[i - 1] / q;
        below += usize::from(q < 0.0);
    }
    q.is_finite().then_some(below)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    #[test]
    fn decomposes_like_nalgebra_with_orthonormal_vectors() {
        for p in [1, 2, 5, 12] {
            let m = DMatrix::from_fn(p, p, |i, j| ((i * 7 + j * 3) % 5) as f64 + (i + j) as f64 * 0.1);
            let sym = &m + m.transpose();
            let mut a: Vec<f64> = (0..p * p).map(|k| sym[(k / p, k % p)]).collect();
            let mut v = vec![0.0; p * p];
            assert!(symmetric_eigen(&mut a, &mut v, p));
            let mut got: Vec<f64> = (0..p).map(|i| a[i * p + i]).collect();
            got.sort_by(f64::total_cmp);
            let mut want = sym.symmetric_eigenvalues().as_slice().to_vec();
            want.sort_by(f64::total_cmp);
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-12 * want.iter().fold(1.0_f64, |s, x| s.max(x.abs())), "p {p}");
            }
            let vm = DMatrix::from_row_slice(p, p, &v);
            assert!((vm.transpose() * &vm - DMatrix::identity(p, p)).amax() < 1e-13);
            let lam = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(p, |i, _| a[i * p + i]));
            let r = (&sym * &vm - &vm * lam).amax();
            assert!(r <= 1e-12 * sym.amax(), "p {p}: residual {r}");
        }
    }

    #[test]
    fn graded_matrix_keeps_small_eigenvalues_relatively_accurate() {
        // diag(1, 1e-10, 1e-20) rotated slightly: the smallest eigenvalue to ~ε relative.
        let d: [f64; 3] = [1.0, 1e-10, 1e-20];
        let mut a = vec![0.0; 9];
        for i in 0..3 {
            a[i * 3 + i] = d[i];
        }
        let c = 1e-3 * (d[0] * d[1]).sqrt();
        a[1] = c;
        a[3] = c;
        let mut v = vec![0.0; 9];
        assert!(symmetric_eigen(&mut a, &mut v, 3));
        assert!((a[8] - 1e-20).abs() < 1e-15 * 1e-20);
    }

    #[test]
    fn nan_input_fails_instead_of_looping() {
        let mut a = vec![1.0, f64::NAN, f64::NAN, 2.0];
        let mut v = vec![0.0; 4];
        assert!(!symmetric_eigen(&mut a, &mut v, 2));
    }

    #[test]
    fn tridiagonal_ql_matches_its_matrix_with_orthonormal_vectors() {
        for n in [1, 2, 7, 15] {
            let d0: Vec<f64> =
                (0..n).map(|i| 1.0 / (1.0 + i as f64).powi(3) + 0.01 * (i % 3) as f64).collect();
            let e0: Vec<f64> = (0..n).map(|i| if i + 1 < n { 0.1 / (1.0 + i as f64) } else { 0.0 }).collect();
            let t = DMatrix::from_fn(n, n, |i, j| match (i, j) {
                _ if i == j => d0[i],
                _ if i + 1 == j => e0[i],
                _ if j + 1 == i => e0[j],
                _ => 0.0,
            });
            let (mut d, mut e) = (d0.clone(), e0.clone());
            let mut z = vec![0.0; n * n];
            assert!(tridiagonal_eigen(&mut d, &mut e, &mut z));
            let vm = DMatrix::from_column_slice(n, n, &z);
            let lam = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&d));
            assert!((&t * &vm - &vm * lam).amax() < 1e-14, "n {n}");
            assert!((vm.transpose() * &vm - DMatrix::identity(n, n)).amax() < 1e-14);
        }
    }

    #[test]
    fn top_pairs_match_ql_or_decline() {
        for n in [1, 2, 5, 9, 20] {
            // A graded positive definite tridiagonal like the ones Lanczos builds on (K⁻¹M).
            let d0: Vec<f64> = (0..n).map(|i| 1.0 / (1.0 + i as f64).powi(2) + 1e-3).collect();
            let e0: Vec<f64> =
                (0..n).map(|i| if i + 1 < n { 0.05 / (1.0 + i as f64) } else { 0.0 }).collect();
            let (mut d, mut e) = (d0.clone(), e0.clone());
            let mut z = vec![0.0; n * n];
            assert!(tridiagonal_eigen(&mut d, &mut e, &mut z));
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| d[b].total_cmp(&d[a]));
            let count = n.min(3);
            let (mut values, mut vectors, mut work) = (Vec::new(), Vec::new(), Vec::new());
            assert!(tridiagonal_top(&d0, &e0, count, &mut values, &mut vectors, &mut work), "n {n}");
            for k in 0..count {
                let want = d[order[k]];
                assert!((values[k] - want).abs() <= 1e-14 * d[order[0]], "n {n} value {k}");
                let col = &z[order[k] * n..(order[k] + 1) * n];
                let dot: f64 = col.iter().zip(&vectors[k * n..(k + 1) * n]).map(|(a, b)| a * b).sum();
                assert!((dot.abs() - 1.0).abs() < 1e-12, "n {n} vector {k}: {dot}");
            }
        }
        // A double eigenvalue cannot be certified as two distinct top pairs: decline.
        let (d, e) = ([2.0, 2.0, 1.0], [0.0, 0.0, 0.0]);
        let (mut values, mut vectors, mut work) = (Vec::new(), Vec::new(), Vec::new());
        assert!(!tridiagonal_top(&d, &e, 2, &mut values, &mut vectors, &mut work));
    }
}
