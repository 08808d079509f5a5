//! Shift-invert Lanczos with full reorthogonalisation: the fast path of
//! [`BandedSolver`](crate::eigen::BandedSolver) and of [`SparseSolver`](crate::eigen::SparseSolver), which
//! differ only in how they store M and factor K + σM ([`ShiftInvert`], [`MassProduct`]).
//!
//! On the inverted operator (K + σM)⁻¹M the lowest modes are the largest, best separated
//! eigenvalues μ = 1/(λ + σ), and a Krylov space finds them in a few steps more than the modes
//! wanted: each step costs one band solve, one band product and the reorthogonalisation, O(n·j).
//! Subspace iteration needs several block iterations of the same cost per vector for the same
//! accuracy. A single start vector cannot see a repeated eigenvalue twice; the caller's Sturm
//! check catches that and falls back to block subspace iteration.

use crate::eigen::{small_eigen::tridiagonal_eigen, small_eigen::tridiagonal_top};
use crate::matrix::{BandCholesky, BandedSymmetric, CscSymmetric};

/// A factor of K + σM: solves (K + σM) x = b in place.
pub(crate) trait ShiftInvert {
    fn solve_in_place(&mut self, x: &mut [f64]);
}

/// The mass matrix's product `out += α·M x`.
pub(crate) trait MassProduct {
    fn dim(&self) -> usize;
    fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]);
}

impl ShiftInvert for BandCholesky {
    fn solve_in_place(&mut self, x: &mut [f64]) {
        BandCholesky::solve_in_place(self, x);
    }
}

impl MassProduct for BandedSymmetric {
    fn dim(&self) -> usize {
        BandedSymmetric::dim(self)
    }
    fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        BandedSymmetric::mul_add(self, alpha, x, out);
    }
}

impl MassProduct for CscSymmetric {
    fn dim(&self) -> usize {
        CscSymmetric::dim(self)
    }
    fn mul_add(&self, alpha: f64, x: &[f64], out: &mut [f64]) {
        CscSymmetric::mul_add(self, alpha, x, out);
    }
}

/// Modes already found (M-orthonormal vectors and their M products, each contiguous) whose span
/// a run must stay out of: a rerun after a Sturm count found a missed mode (a repeated
/// eigenvalue, which one start vector sees once) then finds the missing copies.
#[derive(Clone, Copy)]
pub(crate) struct Locked<'a> {
    pub vectors: &'a [f64],
    pub m_vectors: &'a [f64],
}

/// Reusable work arrays of Lanczos runs (grown on demand, never shrunk).
#[derive(Debug, Default)]
pub(crate) struct LanczosWork {
    /// Basis vectors q₀ … q_j, each contiguous (n per vector).
    q: Vec<f64>,
    /// M qᵢ, same layout: the M inner product (x, qᵢ)_M = xᵀ(M qᵢ) without band products.
    mq: Vec<f64>,
    w: Vec<f64>,
    mw: Vec<f64>,
    alpha: Vec<f64>,
    beta: Vec<f64>,
    ritz: RitzWork,
    coefficients: Vec<f64>,
    start: Vec<f64>,
}

/// Converged Lanczos modes, in the solver's workspace until copied out.
pub(crate) struct Ritz<'a> {
    /// μ = 1/(λ + σ), descending (lowest λ first).
    pub mu: &'a [f64],
    /// Ritz vectors, mode k at `vectors[k·n..(k + 1)·n]`, M-orthonormal.
    pub vectors: &'a [f64],
}

const SINGLE_PASS_STEPS: usize = 8;
/// μ₁/μ_k above which a Ritz value is recomputed as a Rayleigh quotient: below it, T's round-off
/// (a few ε·μ₁) stays under ~1e-13 of θ_k.
const REFINE_SPREAD: f64 = 100.0;
/// Largest true relative inverse residual accepted for a refined Ritz pair.
const TRUE_RESIDUAL_LIMIT: f64 = 1e-6;
/// Steps beyond `count` before the first convergence check: each check is a QL decomposition of
/// T, dearer than a step on small models, and on beam models each step gains about two decades,
/// so fewer steps rarely reach the tolerance.
fn first_check(count: usize, tolerance: f64) -> usize {
    count + ((-tolerance.log10() / 2.0).ceil() as usize).clamp(2, 6)
}
/// Steps allowed before giving up on `count` modes of an n-DOF system.
fn step_limit(n: usize, count: usize) -> usize {
    n.min(4 * count + 40)
}

/// The `count` largest eigenpairs of (K + σM)⁻¹M (factor given) with relative inverse residual
/// ‖ν·Op y − y‖_M ≤ `tolerance` (ν = 1/μ), or `None` when the step limit is reached first.
pub(crate) fn largest<'a>(
    factor: &mut impl ShiftInvert,
    m: &impl MassProduct,
    count: usize,
    tolerance: f64,
    locked: Option<Locked<'_>>,
    work: &'a mut LanczosWork,
) -> Option<Ritz<'a>> {
    let n = m.dim();
    let free = n - locked.map_or(0, |l| l.vectors.len() / n);
    if count > free {
        return None;
    }
    let cap = step_limit(free, count);
    let LanczosWork { q, mq, w, mw, alpha, beta, ritz, coefficients, start } = work;
    // Every entry is written before it is read: the basis grows with the steps taken (not to the
    // step limit: 10⁵ DOFs × 85 vectors would be 136 MB) and is never cleared.
    grow(q, n);
    grow(mq, n);
    // The pseudo-random start vector, generated once per size.
    if start.len() != n {
        start.clear();
        start.extend((0..n).map(|i| pseudo_random(i as u64)));
    }
    w.clear();
    w.extend_from_slice(start);
    mw.clear();
    mw.resize(n, 0.0);
    deflate(w, locked, coefficients);
    alpha.clear();
    beta.clear();
    let mut restarts = 0;
    let norm = m_norm(m, w, mw);
    if !scale_into(w, mw, norm, &mut q[..n], &mut mq[..n]) {
        return None;
    }
    let mut steps = 0;
    while steps < cap {
        let j = steps;
        // w = (K + σM)⁻¹ M qⱼ.
        w.copy_from_slice(&mq[j * n..(j + 1) * n]);
        factor.solve_in_place(w);
        // Full reorthogonalisation, classical Gram–Schmidt twice ("twice is enough"); the
        // coefficient on qⱼ is αⱼ, those on q_{j−1} … q₀ are β_{j−1} and round-off.
        // One pass keeps the short runs of small models orthogonal to round-off. A second
        // ("twice is enough", Kahan–Parlett) for longer runs, and whenever the first cancelled
        // more than three digits of w (a DGKS test, looser than the usual 1/√2 because a
        // converging Lanczos step always cancels much): the rest would be round-off along the
        // basis, as in the last steps of a run through the whole space. In the M norm the
        // removed part is Σcᵢ² (the basis is M-orthonormal), so the test needs no extra product.
        deflate(w, locked, coefficients);
        let mut a = orthogonalise(w, &q[..(j + 1) * n], &mq[..(j + 1) * n], coefficients);
        let mut b = m_norm(m, w, mw);
        let removed: f64 = coefficients.iter().map(|c| c * c).sum();
        if j >= SINGLE_PASS_STEPS || b * b < 1e-6 * (removed + b * b) || locked.is_some() {
            deflate(w, locked, coefficients);
            a += orthogonalise(w, &q[..(j + 1) * n], &mq[..(j + 1) * n], coefficients);
            b = m_norm(m, w, mw);
        }
        alpha.push(a);
        beta.push(b);
        steps += 1;
        if steps >= first_check(count, tolerance).min(n) && converged(alpha, beta, count, tolerance, ritz) {
            break;
        }
        if steps == cap {
            return None;
        }
        // An invariant subspace (β ≈ 0): continue from a fresh direction M-orthogonal to the
        // basis, with a zero coupling in T.
        if b <= 1e-12 * a.abs() {
            restarts += 1;
            for (i, v) in w.iter_mut().enumerate() {
                *v = pseudo_random((restarts * n + i) as u64 + (1 << 40));
            }
            for _ in 0..2 {
                deflate(w, locked, coefficients);
                orthogonalise(w, &q[..steps * n], &mq[..steps * n], coefficients);
            }
            beta[j] = 0.0;
            b = m_norm(m, w, mw);
        }
        grow(q, (steps + 1) * n);
        grow(mq, (steps + 1) * n);
        let (qs, mqs) = (&mut q[steps * n..(steps + 1) * n], &mut mq[steps * n..(steps + 1) * n]);
        if !scale_into(w, mw, b, qs, mqs) {
            return None;
        }
    }
    // `ritz` holds the converged pairs of T.
    let j = steps;
    // Ritz vectors y_k = Σᵢ qᵢ s_{i,k} into w (count·n), μ into alpha.
    w.clear();
    w.resize(count * n, 0.0);
    alpha.clear();
    for k in 0..count {
        let y = &mut w[k * n..(k + 1) * n];
        for i in 0..j {
            axpy(ritz.vectors[k * j + i], &q[i * n..(i + 1) * n], y);
        }
        // T's eigenvalues carry round-off of size ε·μ₁, large against a small μ_k (a high mode
        // next to a soft rigid-body-like one). The inverted Rayleigh quotient
        // μ_k = (My)ᵀ(K + σM)⁻¹(My) / yᵀMy of the converged vector is accurate to μ_k itself;
        // it costs a solve, so it is taken only where T's value could be off by more than 1e-14.
        let theta = ritz.values[k];
        if ritz.values[0] <= REFINE_SPREAD * theta {
            alpha.push(theta);
            continue;
        }
        mw.fill(0.0);
        m.mul_add(1.0, y, mw);
        let z = &mut ritz.scratch;
        z.clear();
        z.extend_from_slice(mw);
        factor.solve_in_place(z);
        let mu = dot(mw, z) / dot(y, mw);
        // Where T's round-off matters, Paige's estimate is least trustworthy too: check the true
        // inverse residual ‖z − μy‖∞ / (μ‖y‖∞) of this vector (z = Op y) and refuse the run when
        // it is far from converged (the caller falls back to block iteration or the dense solver).
        let scale = mu * y.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let residual = z.iter().zip(y.iter()).fold(0.0_f64, |a, (zv, yv)| a.max((zv - mu * yv).abs()));
        if residual.is_nan() || scale.is_nan() || residual > TRUE_RESIDUAL_LIMIT * scale {
            return None;
        }
        alpha.push(mu);
    }
    Some(Ritz { mu: alpha, vectors: w })
}

/// Whether the `count` largest Ritz values of T (α, β) have relative inverse residuals
/// β_last·|s_last,k| / θ_k ≤ `tolerance` (Paige's estimate). Leaves the pairs in `ritz`.
fn converged(alpha: &[f64], beta: &[f64], count: usize, tolerance: f64, ritz: &mut RitzWork) -> bool {
    let j = alpha.len();
    if !ritz.top_pairs(alpha, beta, count) {
        return false;
    }
    let b = beta[j - 1];
    // Round-off floor: a Ritz value far below the largest carries error ε·θ_max, which no number
    // of steps removes (the same limit as the dense solver's inverted reduction).
    let floor = 64.0 * f64::EPSILON * ritz.values[0];
    (0..count).all(|k| {
        let theta = ritz.values[k];
        theta > 0.0 && b * ritz.vectors[k * j + j - 1].abs() <= tolerance * theta + floor
    })
}

/// Most Ritz pairs sought by Rayleigh quotient iteration before QL takes over.
const MAX_RQI_PAIRS: usize = 4;

/// The largest Ritz pairs of the Lanczos matrix T and the work arrays that find them.
#[derive(Debug, Default)]
struct RitzWork {
    /// θ, descending.
    values: Vec<f64>,
    /// Unit eigenvectors of T, one per value, each contiguous.
    vectors: Vec<f64>,
    d: Vec<f64>,
    e: Vec<f64>,
    z: Vec<f64>,
    order: Vec<usize>,
    scratch: Vec<f64>,
}

impl RitzWork {
    /// The `count` largest eigenpairs of T = tridiag(α, β) (β's last entry, the coupling to the
    /// next step, is not part of T): by certified Rayleigh quotient iteration, else by QL.
    fn top_pairs(&mut self, alpha: &[f64], beta: &[f64], count: usize) -> bool {
        // A few pairs: RQI is cheaper than QL. For many, deflated power starts get poor (the
        // ratios θ_{k+1}/θ_k approach 1) and QL, needed anyway, is cheaper than a failed attempt.
        if count <= MAX_RQI_PAIRS
            && tridiagonal_top(alpha, beta, count, &mut self.values, &mut self.vectors, &mut self.scratch)
        {
            return true;
        }
        let j = alpha.len();
        let RitzWork { values, vectors, d, e, z, order, .. } = self;
        d.clear();
        d.extend_from_slice(alpha);
        e.clear();
        e.extend_from_slice(beta);
        z.clear();
        z.resize(j * j, 0.0);
        if !tridiagonal_eigen(d, e, z) {
            return false;
        }
        order.clear();
        order.extend(0..j);
        order.sort_by(|&a, &b| d[b].total_cmp(&d[a]));
        values.clear();
        vectors.clear();
        for &col in order.iter().take(count) {
            values.push(d[col]);
            vectors.extend_from_slice(&z[col * j..(col + 1) * j]);
        }
        true
    }
}

/// One classical Gram–Schmidt pass in the M inner product: w −= Σᵢ (wᵀMqᵢ) qᵢ over the basis
/// `q` (with `mq` = M q). The coefficients are computed first, independently of each other,
/// then applied; returns the last one (αⱼ on the newest vector).
fn orthogonalise(w: &mut [f64], q: &[f64], mq: &[f64], coefficients: &mut Vec<f64>) -> f64 {
    let n = w.len();
    coefficients.clear();
    coefficients.extend(mq.chunks_exact(n).map(|v| dot(w, v)));
    for (&c, v) in coefficients.iter().zip(q.chunks_exact(n)) {
        axpy(-c, v, w);
    }
    coefficients.last().copied().unwrap_or(0.0)
}

/// Removes the locked modes' components from `w` (one Gram–Schmidt pass in the M product).
fn deflate(w: &mut [f64], locked: Option<Locked<'_>>, coefficients: &mut Vec<f64>) {
    if let Some(l) = locked {
        orthogonalise(w, l.vectors, l.m_vectors, coefficients);
    }
}

/// Makes `v` at least `len` long (amortised growth; contents beyond the old length are zero).
fn grow(v: &mut Vec<f64>, len: usize) {
    if v.len() < len {
        v.resize(len, 0.0);
    }
}

/// ‖w‖_M, leaving M w in `mw`.
fn m_norm(m: &impl MassProduct, w: &[f64], mw: &mut [f64]) -> f64 {
    mw.fill(0.0);
    m.mul_add(1.0, w, mw);
    dot(w, mw).max(0.0).sqrt()
}

/// q = w/norm and Mq = Mw/norm; false for a zero or non-finite norm.
fn scale_into(w: &[f64], mw: &[f64], norm: f64, q: &mut [f64], mq: &mut [f64]) -> bool {
    if !(norm > 0.0 && norm.is_finite()) {
        return false;
    }
    for (((qv, mqv), &wv), &mwv) in q.iter_mut().zip(mq.iter_mut()).zip(w).zip(mw) {
        *qv = wv / norm;
        *mqv = mwv / norm;
    }
    true
}

/// aᵀb with four partial sums: a single running sum is a chain of dependent additions.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ac.remainder().iter().zip(bc.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ac.zip(bc) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yv, &xv) in y.iter_mut().zip(x) {
        *yv += alpha * xv;
    }
}

/// splitmix64 at position `k` of a fixed sequence, mapped to [−½, ½): reproducible start vectors.
pub(crate) fn pseudo_random(k: u64) -> f64 {
    let mut z = 0x9E37_79B9_7F4A_7C15_u64.wrapping_mul(k + 1);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}
