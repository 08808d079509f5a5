//! Eigenvectors of a small real upper Hessenberg matrix at eigenvalues already known, by
//! inverse iteration (EISPACK's `invit` scheme): what an Arnoldi convergence check needs for the
//! few dozen wanted Ritz pairs, without the full Schur decomposition and every eigenvector.
//!
//! Each vector costs O(m²) (an LU of the shifted Hessenberg matrix with neighbour pivoting and
//! two solves) against the O(m³) of accumulating Schur vectors: on ROSS's compressor the checks'
//! dense eigen-solves were a quarter of a Campbell sweep.

use faer::{c64, MatRef};

/// Unit eigenvector of the m×m upper Hessenberg `h` for its eigenvalue `theta` (as computed,
/// to round-off). The start is EISPACK's: U x = (1, …, 1) with U from the LU of H − θI (a
/// vanishing pivot is replaced by ε‖H‖, which is what makes the solve amplify the eigenvector),
/// then one full solve (L U x = x) refines it. `None` when the result is not finite.
pub fn eigenvector(h: MatRef<'_, f64>, theta: c64) -> Option<Vec<c64>> {
    let m = h.nrows();
    if m == 0 {
        return None;
    }
    let norm = (0..m)
        .map(|i| (i.saturating_sub(1)..m).map(|j| h[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let tiny = f64::EPSILON * norm;
    // Row-major copy of H − θI; only entries on or right of column i − 1 are nonzero in row i.
    let mut a = vec![c64::new(0.0, 0.0); m * m];
    for i in 0..m {
        for j in i.saturating_sub(1)..m {
            a[i * m + j] = c64::new(h[(i, j)], 0.0);
        }
        a[i * m + i] -= theta;
    }
    let mut swapped = vec![false; m];
    let mut l = vec![c64::new(0.0, 0.0); m];
    for k in 0..m - 1 {
        // Only row k + 1 has a nonzero below the diagonal in column k: pivot between the two.
        if a[(k + 1) * m + k].norm_sqr() > a[k * m + k].norm_sqr() {
            for j in k..m {
                a.swap(k * m + j, (k + 1) * m + j);
            }
            swapped[k] = true;
        }
        if a[k * m + k] == c64::new(0.0, 0.0) {
            a[k * m + k] = c64::new(tiny, 0.0);
        }
        let factor = a[(k + 1) * m + k] / a[k * m + k];
        l[k] = factor;
        if factor != c64::new(0.0, 0.0) {
            let (top, bottom) = a.split_at_mut((k + 1) * m);
            let pivot_row = &top[k * m + k + 1..k * m + m];
            bottom[k + 1..m].iter_mut().zip(pivot_row).for_each(|(x, p)| *x -= factor * p);
        }
    }
    if a[(m - 1) * m + m - 1] == c64::new(0.0, 0.0) {
        a[(m - 1) * m + m - 1] = c64::new(tiny, 0.0);
    }
    let back = |x: &mut [c64]| {
        for i in (0..m).rev() {
            let row = &a[i * m + i + 1..i * m + m];
            let s: c64 = row.iter().zip(&x[i + 1..]).map(|(p, q)| p * q).sum();
            x[i] = (x[i] - s) / a[i * m + i];
        }
    };
    let normalise = |x: &mut [c64]| -> Option<()> {
        let n = x.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
        if !n.is_finite() || n == 0.0 {
            return None;
        }
        x.iter_mut().for_each(|v| *v /= n);
        Some(())
    };
    let mut x = vec![c64::new(1.0, 0.0); m];
    back(&mut x);
    normalise(&mut x)?;
    for k in 0..m - 1 {
        if swapped[k] {
            x.swap(k, k + 1);
        }
        let xk = x[k];
        x[k + 1] -= l[k] * xk;
    }
    back(&mut x);
    normalise(&mut x)?;
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// The vectors satisfy H s = θ s to round-off, for real and complex eigenvalues, as the full
    /// eigendecomposition's do.
    #[test]
    fn inverse_iteration_gives_the_eigenvectors_of_a_hessenberg_matrix() {
        let m = 12;
        let h = Mat::from_fn(m, m, |i, j| {
            if i > j + 1 {
                0.0
            } else {
                ((i * 5 + j * 3) % 7) as f64 - 2.5 + if i == j { i as f64 } else { 0.0 }
            }
        });
        let values = h.eigenvalues().unwrap();
        assert!(values.iter().any(|v| v.im.abs() > 1e-3), "some complex pair in the test matrix");
        for theta in values {
            let s = eigenvector(h.as_ref(), theta).unwrap();
            let mut worst = 0.0_f64;
            for i in 0..m {
                let hs: c64 = (0..m).map(|j| s[j] * h[(i, j)]).sum();
                worst = worst.max((hs - theta * s[i]).norm());
            }
            assert!(worst < 1e-12 * theta.norm().max(1.0), "θ = {theta}: ‖Hs − θs‖ = {worst:e}");
        }
    }
}
