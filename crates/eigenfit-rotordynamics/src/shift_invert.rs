//! The lowest modes of a large rotor without the dense 2n eigen-solve: Arnoldi on the
//! shift-inverted state-space operator A⁻¹, applied through a band LU of the n×n stiffness K
//! (a rotor's matrices are banded: each node couples to its neighbours only), with the mass and
//! velocity matrices applied by band. The eigenvalues nearest 0 converge first; they are the
//! low modes. The Krylov basis grows only until the modes returned have converged and every
//! other wanted Ritz pair ranks above them (checked every few steps, from the Ritz values and
//! inverse-iteration vectors of the small Hessenberg matrix), and is orthogonalised by
//! matrix–vector products (faer's SIMD kernels).

use crate::band::{Band, BandLu};
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{evd_real, evd_scratch, ComputeEigenvectors};
use faer::linalg::matmul::matmul;
use faer::{c64, Accum, Col, Mat, Par};

/// Krylov steps between two convergence checks (each check is a small dense eigen-solve).
const CHECK_EVERY: usize = 6;

/// Relative Arnoldi residual the modes returned must reach: |β sₘ|/‖s‖ ≤ this · |θ|. 1e-10 was
/// enough while the spares' 1e-8 kept every solve going well past it; stopped there, a heavily
/// damped mode of ROSS's compressor (ζ 0.28 at 0 rpm) ended 1.7e-9 from the dense solve.
const RESIDUAL: f64 = 1e-12;

/// Relative Arnoldi residual the other wanted Ritz pairs must reach: enough to rank them by
/// damped frequency against the modes returned (their eigenvalues are then good to ~1e-8) —
/// unless [`RANKING_MARGIN`] already ranks them.
const RANKING_RESIDUAL: f64 = 1e-8;

/// A wanted Ritz pair that is not returned is ranked (above the modes returned) once its damped
/// frequency |Im λ| exceeds the highest returned one by this many times its error estimate
/// r·|λ| (r its relative residual; |δθ| ≤ r|θ| for a normal operator, and δλ = δθ/θ²; the factor
/// covers non-normality). Such a pair needs no more steps: on ROSS's compressor the returned
/// modes reach 1e-10 at about 1.3 steps per wanted eigenvalue, but the spares at the far end of
/// the wanted set (2.8 kHz, against a 1.2 kHz highest returned mode) took 1.9 to reach 1e-8.
const RANKING_MARGIN: f64 = 1e3;

/// Eigenpairs (λ, right state-vector's displacement part) of (λ²M + λD + K)x = 0 near 0: of the
/// `wanted` eigenvalues nearest 0 (counting each conjugate separately), the `exact` oscillating
/// ones (Im λ > 0) of lowest damped frequency Im λ (fewer when fewer oscillate), converged to
/// an Arnoldi residual below 1e-12 relative; the other wanted ones, which only rank them, have
/// converged below 1e-8 or lie far enough above them in damped frequency for their error
/// estimate (`RANKING_MARGIN`). The Krylov
/// space starts from a fixed generic vector: results do not depend on a random seed (nor on
/// other speeds: starting from the modes of the previous speed of a sweep was tried and saved
/// no step on ROSS's compressor). `None` when the band LU fails (K singular: a free
/// rotor) or the Krylov space would exceed the problem; the caller then solves densely.
pub fn nearest_zero(
    m: &Band,
    d: &Band,
    k: &Band,
    wanted: usize,
    exact: usize,
) -> Option<Vec<(c64, Vec<c64>)>> {
    let n = m.dim();
    // A band wider than a quarter of the matrix gains nothing over the dense solve.
    let width = [m, d, k].iter().map(|a| a.lower() + a.upper()).max().unwrap_or(0);
    if 4 * width > n {
        return None;
    }
    let lu = BandLu::new(k)?;
    let size = 2 * n;
    let max_dim = size - 1;
    // Shift-invert Arnoldi needs about 1.15–1.7 steps per wanted eigenvalue on a rotor (42–61
    // for 36 on ROSS's compressor): checking before that would only cost small eigen-solves
    // (first at 1.2, 1.3 or 1.4 and every 5 or 6 steps on, the sweep's time was least at 1.3, 6).
    let first_check = (wanted * 13).div_ceil(10).max(wanted + CHECK_EVERY).min(max_dim);
    // Op u = A⁻¹u: x2 = u1, K x1 = −M u2 − D u1.
    let op = |u: &[f64], out: &mut [f64]| {
        let (u1, u2) = u.split_at(n);
        let (o1, o2) = out.split_at_mut(n);
        o1.iter_mut().for_each(|v| *v = 0.0);
        Band::mul_add_pair(m, u2, d, u1, -1.0, o1);
        lu.solve(o1);
        o2.copy_from_slice(u1);
    };
    // Basis and Hessenberg matrix grow as the steps need them (a whole 2n × 2n basis would be
    // megabytes of zeros for the few dozen vectors a solve takes).
    let mut cap = (first_check + CHECK_EVERY).min(max_dim);
    // The basis of the last solve on this thread, reused: a fresh one per speed of a sweep
    // (600 kB on ROSS's compressor) cost 8 % of the sweep in page faults (perf).
    let mut v = BASIS.with(|b| b.take()).filter(|v| v.nrows() == size).unwrap_or_else(|| Mat::zeros(size, 0));
    if v.ncols() < cap + 1 {
        v.resize_with(size, cap + 1, |_, _| 0.0);
    }
    let found = arnoldi(&mut v, &op, &mut cap, Krylov { n, max_dim, first_check, wanted, exact });
    BASIS.with(|b| b.replace(Some(v)));
    found
}

thread_local! {
    /// [`nearest_zero`]'s Krylov basis, kept between solves on this thread.
    static BASIS: std::cell::RefCell<Option<Mat<f64>>> = const { std::cell::RefCell::new(None) };
}

/// Sizes of one [`nearest_zero`] solve.
struct Krylov {
    n: usize,
    max_dim: usize,
    first_check: usize,
    wanted: usize,
    exact: usize,
}

/// The Arnoldi loop of [`nearest_zero`] on the basis `v` (columns beyond the steps taken are
/// stale: each is written before it is read).
fn arnoldi(
    v: &mut Mat<f64>,
    op: &dyn Fn(&[f64], &mut [f64]),
    cap: &mut usize,
    k: Krylov,
) -> Option<Vec<(c64, Vec<c64>)>> {
    let Krylov { n, max_dim, first_check, wanted, exact } = k;
    let size = 2 * n;
    generic_start(size).iter().enumerate().for_each(|(i, x)| v[(i, 0)] = *x);
    let mut h = Mat::<f64>::zeros(*cap + 1, *cap);
    let mut w = Col::<f64>::zeros(size);
    let mut c = Col::<f64>::zeros(max_dim + 1);
    let mut next_check = first_check;
    for j in 0..max_dim {
        if j == *cap {
            *cap = (2 * *cap).min(max_dim);
            if v.ncols() < *cap + 1 {
                v.resize_with(size, *cap + 1, |_, _| 0.0);
            }
            h.resize_with(*cap + 1, *cap, |_, _| 0.0);
        }
        op(
            v.col(j).try_as_col_major().unwrap().as_slice(),
            w.as_mut().try_as_col_major_mut().unwrap().as_slice_mut(),
        );
        count(1, 0);
        // Classical Gram–Schmidt twice, by matrix–vector products, keeps the basis orthogonal to
        // working precision.
        let basis = v.as_ref().subcols(0, j + 1);
        for _ in 0..2 {
            matmul(
                c.as_mut().subrows_mut(0, j + 1),
                Accum::Replace,
                basis.transpose(),
                w.as_ref(),
                1.0,
                Par::Seq,
            );
            let cj = c.as_ref().subrows(0, j + 1);
            matmul(w.as_mut(), Accum::Add, basis, cj, -1.0, Par::Seq);
            for i in 0..=j {
                h[(i, j)] += cj[i];
            }
        }
        let beta = w.norm_l2();
        h[(j + 1, j)] = beta;
        let steps = j + 1;
        let invariant = beta < 1e-300;
        if !invariant {
            v.col_mut(j + 1).copy_from(w.as_ref() * faer::Scale(1.0 / beta));
        }
        if invariant || steps == next_check || steps == max_dim {
            count(0, 1);
            if let Some(found) = ritz(v, &h, n, steps, wanted, exact) {
                return Some(found);
            }
            if invariant {
                return None;
            }
            next_check = steps + CHECK_EVERY;
        }
    }
    None
}

/// Work done by [`nearest_zero`] on this thread since it started: how many times the shifted
/// operator was applied (one band solve each) and how many convergence checks (small dense
/// eigen-solves) were made. For tests and benchmarks that bound the work of a sweep.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Work {
    /// Applications of the shift-inverted operator (Krylov steps).
    pub applications: u64,
    /// Convergence checks.
    pub checks: u64,
}

thread_local! {
    static WORK: std::cell::Cell<Work> = const { std::cell::Cell::new(Work { applications: 0, checks: 0 }) };
}

/// The work [`nearest_zero`] has done on this thread so far (see [`Work`]).
pub fn work() -> Work {
    WORK.with(|w| w.get())
}

fn count(applications: u64, checks: u64) {
    WORK.with(|w| {
        let mut v = w.get();
        v.applications += applications;
        v.checks += checks;
        w.set(v);
    });
}

/// Whether an eigenvalue is the positive-frequency member of an oscillating pair: Im λ > 0 by
/// more than round-off relative to |λ| (a real eigenvalue's round-off imaginary part is not).
pub fn oscillates(lambda: c64) -> bool {
    lambda.im > 1e-9 * lambda.norm().max(1e-12)
}

/// A fixed, generic unit vector of `size` entries (no random seed: results are reproducible).
pub fn generic_start(size: usize) -> Vec<f64> {
    let v: Vec<f64> = (0..size).map(|i| 1.0 + 0.5 * ((i as f64) * 0.73).sin()).collect();
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.into_iter().map(|x| x / norm).collect()
}

/// Of the `wanted` Ritz pairs of largest |θ| of the Arnoldi factorisation with `steps` vectors,
/// the `exact` oscillating ones of lowest damped frequency, as (λ = 1/θ, displacement part of the
/// Ritz vector); `None` while any wanted pair has not converged (the `exact` to [`RESIDUAL`], the
/// others to [`RANKING_RESIDUAL`] or [`RANKING_MARGIN`]).
///
/// The Ritz values come from an eigenvalues-only Hessenberg QR ([`crate::hessenberg`]) and the wanted pairs' vectors
/// from inverse iteration ([`crate::hessenberg`]): O(m²) each instead of the Schur vectors'
/// O(m³). When two wanted Ritz values lie closer than [`CLUSTER`] (inverse iteration would give
/// both nearly the same vector) the full eigendecomposition gives them instead.
fn ritz(
    v: &Mat<f64>,
    h: &Mat<f64>,
    n: usize,
    steps: usize,
    wanted: usize,
    exact: usize,
) -> Option<Vec<(c64, Vec<c64>)>> {
    if steps < wanted {
        return None;
    }
    let hm = h.as_ref().submatrix(0, 0, steps, steps).to_owned();
    let beta_last = h[(steps, steps - 1)];
    // EISPACK's QR on the Hessenberg matrix as it is; faer's (which reduces it again) if that
    // does not converge.
    let values = match crate::hessenberg::eigenvalues(hm.as_ref()) {
        Some(values) => values,
        None => hessenberg_eigen(&hm, false)?.0,
    };
    let chosen = largest(&values, wanted);
    let thetas: Vec<c64> = chosen.iter().map(|&i| values[i]).collect();
    let scale = thetas.iter().map(|t| t.norm()).fold(0.0, f64::max);
    let clustered = thetas.iter().enumerate().any(|(a, ta)| {
        thetas[a + 1..].iter().any(|tb| *tb != ta.conj() && (ta - tb).norm() <= CLUSTER * scale)
    });
    let full = if clustered { Some(hessenberg_eigen(&hm, true)?) } else { None };
    let thetas: Vec<c64> = match &full {
        Some((values, _)) => largest(values, wanted).iter().map(|&i| values[i]).collect(),
        None => thetas,
    };
    let full_vectors: Option<Vec<Vec<c64>>> = full.map(|(values, vectors)| {
        let vectors = vectors.unwrap_or_default();
        largest(&values, wanted).iter().map(|&i| vectors[i].clone()).collect()
    });
    // Vectors on demand, so that a check fails after the few its first failing pair needs;
    // one inverse iteration per conjugate pair (the other member's vector is its conjugate).
    let mut vectors: Vec<Option<Vec<c64>>> = vec![None; thetas.len()];
    let mut vector = |col: usize| -> Option<Vec<c64>> {
        if let Some(full) = &full_vectors {
            return Some(full[col].clone());
        }
        if vectors[col].is_none() {
            let theta = thetas[col];
            let partner =
                (0..thetas.len()).find(|&p| p != col && theta.im != 0.0 && thetas[p] == theta.conj());
            let s = match partner.and_then(|p| vectors[p].as_ref()) {
                Some(s) => s.iter().map(|x| x.conj()).collect(),
                None => crate::hessenberg::eigenvector(hm.as_ref(), theta)?,
            };
            vectors[col] = Some(s);
        }
        vectors[col].clone()
    };
    // Relative residual |β sₘ|/(‖s‖|θ|) of a Ritz pair.
    let residual = |s: &[c64], theta: c64| {
        let snorm = s.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
        beta_last * s[steps - 1].norm() / snorm / theta.norm()
    };
    // The modes returned: the oscillating ones of lowest damped frequency.
    let lambdas: Vec<c64> = thetas.iter().map(|t| t.inv()).collect();
    let mut oscillating: Vec<usize> = (0..lambdas.len()).filter(|&i| oscillates(lambdas[i])).collect();
    oscillating.sort_by(|&a, &b| lambdas[a].im.total_cmp(&lambdas[b].im));
    let returned = &oscillating[..exact.min(oscillating.len())];
    let mut residuals = vec![f64::NAN; thetas.len()];
    for &i in returned {
        residuals[i] = residual(&vector(i)?, thetas[i]);
        if residuals[i].is_nan() || residuals[i] > RESIDUAL {
            return None;
        }
    }
    // The others only have to rank above the modes returned (with fewer oscillating pairs than
    // asked for, nothing ranks them: each must converge to the ranking residual).
    let cutoff = match returned.last() {
        Some(&last) if returned.len() == exact => lambdas[last].im,
        _ => f64::INFINITY,
    };
    for i in (0..thetas.len()).filter(|i| !returned.contains(i)) {
        let r = residual(&vector(i)?, thetas[i]);
        let ranked =
            r <= RANKING_RESIDUAL || lambdas[i].im.abs() - cutoff >= RANKING_MARGIN * r * lambdas[i].norm();
        if !ranked {
            return None;
        }
    }
    // The returned Ritz vectors' coefficients (real and imaginary parts as columns).
    let mut s_parts = Mat::<f64>::zeros(steps, 2 * returned.len());
    for (col, &i) in returned.iter().enumerate() {
        for (row, x) in vector(i)?.iter().enumerate() {
            s_parts[(row, 2 * col)] = x.re;
            s_parts[(row, 2 * col + 1)] = x.im;
        }
    }
    // Their displacement halves: X = V[..n] S, one product for all.
    let mut x = Mat::<f64>::zeros(n, 2 * returned.len());
    matmul(x.as_mut(), Accum::Replace, v.as_ref().submatrix(0, 0, n, steps), s_parts.as_ref(), 1.0, Par::Seq);
    Some(
        returned
            .iter()
            .enumerate()
            .map(|(col, &i)| {
                (lambdas[i], (0..n).map(|r| c64::new(x[(r, 2 * col)], x[(r, 2 * col + 1)])).collect())
            })
            .collect(),
    )
}

/// Two wanted Ritz values closer than this (relative to the largest |θ|) are a cluster: their
/// vectors come from the full eigendecomposition, not inverse iteration.
const CLUSTER: f64 = 1e-6;

/// Indices of the `wanted` values of largest modulus (nearest λ = 0), largest first.
fn largest(values: &[c64], wanted: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[b].norm().total_cmp(&values[a].norm()));
    order.truncate(wanted.min(values.len()));
    order
}

type Eigen = (Vec<c64>, Option<Vec<Vec<c64>>>);

/// Eigenvalues of the small Hessenberg matrix and, `with_vectors`, every eigenvector (unit
/// 2-norm, complex), unpacked from LAPACK's real storage of conjugate pairs.
fn hessenberg_eigen(hm: &Mat<f64>, with_vectors: bool) -> Option<Eigen> {
    let steps = hm.nrows();
    let mut ur = Mat::<f64>::zeros(steps, steps);
    let mut s_re = Diag::<f64>::zeros(steps);
    let mut s_im = Diag::<f64>::zeros(steps);
    let want = if with_vectors { ComputeEigenvectors::Yes } else { ComputeEigenvectors::No };
    let mut mem = MemBuffer::new(evd_scratch::<f64>(
        steps,
        ComputeEigenvectors::No,
        want,
        Par::Seq,
        Default::default(),
    ));
    evd_real(
        hm.as_ref(),
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        if with_vectors { Some(ur.as_mut()) } else { None },
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let (s_re, s_im) = (s_re.column_vector(), s_im.column_vector());
    let values: Vec<c64> = (0..steps).map(|i| c64::new(s_re[i], s_im[i])).collect();
    if !with_vectors {
        return Some((values, None));
    }
    let vectors = (0..steps)
        .map(|idx| {
            let complex_first =
                s_im[idx] != 0.0 && idx + 1 < steps && s_im[idx] > 0.0 && s_im[idx + 1] == -s_im[idx];
            let complex_second =
                s_im[idx] != 0.0 && idx > 0 && s_im[idx - 1] == -s_im[idx] && s_im[idx] < 0.0;
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
            let norm = s.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
            s.into_iter().map(|x| x / norm).collect()
        })
        .collect();
    Some((values, Some(vectors)))
}
