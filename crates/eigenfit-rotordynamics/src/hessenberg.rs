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

/// Eigenvalues of the m×m upper Hessenberg `h` by the double-shift QR algorithm (EISPACK's
/// `hqr`: Francis steps on the active window only, no Schur form or vectors kept, exceptional
/// shifts after 10 and 20 iterations). Conjugate pairs come out next to each other, the one with
/// positive imaginary part first. `None` when an eigenvalue takes more than 30 iterations.
///
/// faer's eigenvalues-only route reduces its input to Hessenberg form first, which for a matrix
/// already Hessenberg is work for nothing; with the QR's 3-element reflectors inline this is
/// the cheaper of the two for the few dozen rows of an Arnoldi check.
pub fn eigenvalues(h: MatRef<'_, f64>) -> Option<Vec<c64>> {
    let n = h.nrows() as isize;
    let mut a: Vec<f64> = vec![0.0; (n * n) as usize];
    let at = |i: isize, j: isize| (i * n + j) as usize;
    for i in 0..n {
        for j in (i - 1).max(0)..n {
            a[at(i, j)] = h[(i as usize, j as usize)];
        }
    }
    let anorm: f64 = a.iter().map(|v| v.abs()).sum();
    let (mut wr, mut wi) = (vec![0.0; n as usize], vec![0.0; n as usize]);
    let mut nn = n - 1;
    let mut t = 0.0;
    while nn >= 0 {
        let mut its = 0;
        loop {
            // A negligible subdiagonal entry splits the active window at l.
            let mut l = nn;
            while l >= 1 {
                let mut s = a[at(l - 1, l - 1)].abs() + a[at(l, l)].abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a[at(l, l - 1)].abs() + s == s {
                    a[at(l, l - 1)] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[at(nn, nn)];
            if l == nn {
                wr[nn as usize] = x + t;
                wi[nn as usize] = 0.0;
                nn -= 1;
                break;
            }
            let mut y = a[at(nn - 1, nn - 1)];
            let mut w = a[at(nn, nn - 1)] * a[at(nn - 1, nn)];
            if l == nn - 1 {
                // A 2×2 block: two real roots or a conjugate pair.
                let p = 0.5 * (y - x);
                let q = p * p + w;
                let z = q.abs().sqrt();
                x += t;
                let (i0, i1) = ((nn - 1) as usize, nn as usize);
                if q >= 0.0 {
                    let z = p + z.copysign(p);
                    wr[i0] = x + z;
                    wr[i1] = if z != 0.0 { x - w / z } else { x + z };
                    wi[i0] = 0.0;
                    wi[i1] = 0.0;
                } else {
                    wr[i0] = x + p;
                    wr[i1] = x + p;
                    wi[i0] = z;
                    wi[i1] = -z;
                }
                nn -= 2;
                break;
            }
            if its == 30 {
                return None;
            }
            if its == 10 || its == 20 {
                // Exceptional shift.
                t += x;
                for i in 0..=nn {
                    a[at(i, i)] -= x;
                }
                let s = a[at(nn, nn - 1)].abs() + a[at(nn - 1, nn - 2)].abs();
                x = 0.75 * s;
                y = x;
                w = -0.4375 * s * s;
            }
            its += 1;
            // Two consecutive small subdiagonal entries: the double step starts at m.
            let mut m = nn - 2;
            let (mut p, mut q, mut r);
            loop {
                let z = a[at(m, m)];
                let rr = x - z;
                let ss = y - z;
                p = (rr * ss - w) / a[at(m + 1, m)] + a[at(m, m + 1)];
                q = a[at(m + 1, m + 1)] - z - rr - ss;
                r = a[at(m + 2, m + 1)];
                let s = p.abs() + q.abs() + r.abs();
                p /= s;
                q /= s;
                r /= s;
                if m == l {
                    break;
                }
                let u = a[at(m, m - 1)].abs() * (q.abs() + r.abs());
                let v = p.abs() * (a[at(m - 1, m - 1)].abs() + z.abs() + a[at(m + 1, m + 1)].abs());
                if u + v == v {
                    break;
                }
                m -= 1;
            }
            for i in m + 2..=nn {
                a[at(i, i - 2)] = 0.0;
                if i != m + 2 {
                    a[at(i, i - 3)] = 0.0;
                }
            }
            // The double QR step on rows l..=nn and columns m..=nn.
            let mut k = m;
            while k < nn {
                if k != m {
                    p = a[at(k, k - 1)];
                    q = a[at(k + 1, k - 1)];
                    r = if k != nn - 1 { a[at(k + 2, k - 1)] } else { 0.0 };
                    x = p.abs() + q.abs() + r.abs();
                    if x != 0.0 {
                        p /= x;
                        q /= x;
                        r /= x;
                    }
                }
                let s = (p * p + q * q + r * r).sqrt().copysign(p);
                if s != 0.0 {
                    if k == m {
                        if l != m {
                            a[at(k, k - 1)] = -a[at(k, k - 1)];
                        }
                    } else {
                        a[at(k, k - 1)] = -s * x;
                    }
                    p += s;
                    x = p / s;
                    y = q / s;
                    let z = r / s;
                    q /= p;
                    r /= p;
                    for j in k..=nn {
                        let mut pp = a[at(k, j)] + q * a[at(k + 1, j)];
                        if k != nn - 1 {
                            pp += r * a[at(k + 2, j)];
                            a[at(k + 2, j)] -= pp * z;
                        }
                        a[at(k + 1, j)] -= pp * y;
                        a[at(k, j)] -= pp * x;
                    }
                    let mmin = if nn < k + 3 { nn } else { k + 3 };
                    for i in l..=mmin {
                        let mut pp = x * a[at(i, k)] + y * a[at(i, k + 1)];
                        if k != nn - 1 {
                            pp += z * a[at(i, k + 2)];
                            a[at(i, k + 2)] -= pp * r;
                        }
                        a[at(i, k + 1)] -= pp * q;
                        a[at(i, k)] -= pp;
                    }
                }
                k += 1;
            }
        }
    }
    Some(wr.into_iter().zip(wi).map(|(re, im)| c64::new(re, im)).collect())
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
        // The QR's eigenvalues are faer's, each to round-off.
        let ours = eigenvalues(h.as_ref()).unwrap();
        assert_eq!(ours.len(), m);
        for v in &values {
            let nearest = ours.iter().map(|o| (o - v).norm()).fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-12 * v.norm().max(1.0), "{v}: nearest {nearest:e}");
        }
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
