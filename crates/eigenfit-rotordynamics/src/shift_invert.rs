//! The lowest modes of a large rotor without the dense 2n eigen-solve: Arnoldi on the
//! shift-inverted state-space operator A⁻¹, applied through a band LU of the n×n stiffness K
//! (a rotor's matrices are banded: each node couples to its neighbours only), with the mass and
//! velocity matrices applied by band. The eigenvalues nearest 0 converge first; they are the
//! low modes. The Krylov basis grows only until every wanted Ritz pair has converged (checked
//! every few steps), and is orthogonalised by matrix–vector products (faer's SIMD kernels).

use crate::band::{Band, BandLu};
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{evd_real, evd_scratch, ComputeEigenvectors};
use faer::linalg::matmul::matmul;
use faer::{c64, Accum, Col, Mat, Par};

/// Krylov steps between two convergence checks (each check is a small dense eigen-solve).
const CHECK_EVERY: usize = 6;

/// Relative Arnoldi residual the modes returned must reach: |β sₘ|/‖s‖ ≤ this · |θ|.
const RESIDUAL: f64 = 1e-10;

/// Relative Arnoldi residual the other wanted Ritz pairs must reach: enough to rank them by
/// damped frequency against the modes returned (their eigenvalues are then good to ~1e-8).
const RANKING_RESIDUAL: f64 = 1e-8;

/// Eigenpairs (λ, right state-vector's displacement part) of (λ²M + λD + K)x = 0 nearest 0:
/// the `wanted` eigenvalues nearest 0 (counting each conjugate separately), of which the `exact`
/// oscillating ones (Im λ > 0) of lowest damped frequency Im λ have converged to an Arnoldi
/// residual below 1e-10 relative and the others, which only rank them, below 1e-8. The Krylov
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
    // Shift-invert Arnoldi needs about 1.9 steps per wanted eigenvalue on a rotor (63–75, 69
    // on most speeds, for 36 on ROSS's compressor): checking before that would only cost small
    // eigen-solves, each the price of several steps.
    let first_check = (wanted * 19).div_ceil(10).max(wanted + CHECK_EVERY).min(max_dim);
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
    let mut v = Mat::<f64>::zeros(size, cap + 1);
    generic_start(size).iter().enumerate().for_each(|(i, x)| v[(i, 0)] = *x);
    let mut h = Mat::<f64>::zeros(cap + 1, cap);
    let mut w = Col::<f64>::zeros(size);
    let mut c = Col::<f64>::zeros(max_dim + 1);
    let mut next_check = first_check;
    for j in 0..max_dim {
        if j == cap {
            cap = (2 * cap).min(max_dim);
            v.resize_with(size, cap + 1, |_, _| 0.0);
            h.resize_with(cap + 1, cap, |_, _| 0.0);
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
            if let Some(found) = ritz(&v, &h, n, steps, wanted, exact) {
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

/// The `wanted` Ritz pairs of largest |θ| of the Arnoldi factorisation with `steps` vectors, as
/// (λ = 1/θ, displacement part of the Ritz vector); `None` while any has not converged (the
/// `exact` of lowest damped frequency to [`RESIDUAL`], the others to [`RANKING_RESIDUAL`]).
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
    // The wanted eigenvalues are the largest |θ| (nearest λ = 0); each must have converged.
    let mut order: Vec<usize> = (0..steps).collect();
    order.sort_by(|&a, &b| {
        let ta = c64::new(s_re[a], s_im[a]).norm();
        let tb = c64::new(s_re[b], s_im[b]).norm();
        tb.total_cmp(&ta)
    });
    let chosen = &order[..wanted.min(steps)];
    // Each chosen Ritz vector's coefficients (real and imaginary parts as columns).
    let mut s_parts = Mat::<f64>::zeros(steps, 2 * chosen.len());
    let mut thetas = Vec::with_capacity(chosen.len());
    let mut residuals = Vec::with_capacity(chosen.len());
    for (col, &idx) in chosen.iter().enumerate() {
        let theta = c64::new(s_re[idx], s_im[idx]);
        let complex_first =
            s_im[idx] != 0.0 && idx + 1 < steps && s_im[idx] > 0.0 && s_im[idx + 1] == -s_im[idx];
        let complex_second = s_im[idx] != 0.0 && idx > 0 && s_im[idx - 1] == -s_im[idx] && s_im[idx] < 0.0;
        let mut snorm = 0.0;
        for i in 0..steps {
            let (re, im) = if complex_first {
                (ur[(i, idx)], ur[(i, idx + 1)])
            } else if complex_second {
                (ur[(i, idx - 1)], -ur[(i, idx)])
            } else {
                (ur[(i, idx)], 0.0)
            };
            s_parts[(i, 2 * col)] = re;
            s_parts[(i, 2 * col + 1)] = im;
            snorm += re * re + im * im;
        }
        let last = c64::new(s_parts[(steps - 1, 2 * col)], s_parts[(steps - 1, 2 * col + 1)]);
        let residual = beta_last * last.norm() / snorm.sqrt() / theta.norm();
        if residual.is_nan() || residual > RANKING_RESIDUAL {
            return None;
        }
        thetas.push(theta);
        residuals.push(residual);
    }
    // The modes returned: the oscillating ones of lowest damped frequency.
    let lambdas: Vec<c64> = thetas.iter().map(|t| t.inv()).collect();
    let mut oscillating: Vec<usize> = (0..lambdas.len()).filter(|&i| oscillates(lambdas[i])).collect();
    oscillating.sort_by(|&a, &b| lambdas[a].im.total_cmp(&lambdas[b].im));
    if oscillating.iter().take(exact).any(|&i| residuals[i] > RESIDUAL) {
        return None;
    }
    // Ritz vectors' displacement halves: X = V[..n] S, one product for all.
    let mut x = Mat::<f64>::zeros(n, 2 * chosen.len());
    matmul(x.as_mut(), Accum::Replace, v.as_ref().submatrix(0, 0, n, steps), s_parts.as_ref(), 1.0, Par::Seq);
    Some(
        thetas
            .into_iter()
            .enumerate()
            .map(|(col, theta)| {
                (theta.inv(), (0..n).map(|r| c64::new(x[(r, 2 * col)], x[(r, 2 * col + 1)])).collect())
            })
            .collect(),
    )
}
