//! The banded eigen-solver, for beam models of every size — the paper rotor's 22 DOFs in a few
//! microseconds, 10⁴ DOFs in milliseconds: shift-invert Lanczos on a band Cholesky factor
//! (`lanczos.rs`), with block subspace iteration (here) and the dense solver as fallbacks.

use crate::eigen::lanczos::{self, pseudo_random, LanczosWork};
use crate::eigen::small_eigen::symmetric_eigen;
use crate::eigen::solver::request_tolerance;
use crate::eigen::{
    apply_sign_rule, check_count, shifted_twice, DenseSolver, EigenSolver, ModeRequest, Modes, SolveError,
    SolvedModes,
};
use crate::matrix::{BandCholesky, BandedSymmetric, System};
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

/// Lowest modes of banded systems (beam meshes), O(n·b²) to factor and O(n·(b + j)) per Lanczos
/// step, without allocating beyond the returned modes.
///
/// K + σM = LLᵀ is factored once by band (b = 3 for beam models; σ = 0 when K is positive
/// definite, otherwise the dense solver's tiny σ₀ and then the lowest elastic eigenvalue). Lanczos
/// with full reorthogonalisation on (K + σM)⁻¹M, whose largest eigenvalues μ = 1/(λ + σ) are the
/// lowest modes, finds them in a few steps more than the modes wanted; a mode counts as converged
/// when its relative inverse residual ‖ν·Op y − y‖_M (ν = 1/μ) — the relative error of its shape,
/// the eigenvalue's being about its square — falls below [`tolerance`](Self::tolerance), or to
/// the round-off floor ε·μ₁. Eigenvalues are accurate relative to themselves, as the dense
/// solver's inverted reduction makes them.
///
/// A Sturm count (the negative pivots of K − σ′M = LDLᵀ just above the highest mode found) then
/// proves no lower mode was missed, and σ′ is returned by
/// [`lowest_with_next`](EigenSolver::lowest_with_next) as a lower bound on the next eigenvalue.
/// If a mode was missed (a repeated eigenvalue: one start vector sees it once) or Lanczos does
/// not converge, block subspace iteration (Bathe; Rayleigh–Ritz in the same inverted form, by
/// Jacobi) takes over; if it too misses a mode, stops short of the tolerance, or more than half
/// the modes are requested, [`DenseSolver`] (up to [`DENSE_MAX_DOFS`](super::DENSE_MAX_DOFS)
/// DOFs; beyond, a subspace iteration that stops improving below 1e-6 is taken as at its floor).
///
/// All work arrays live in a per-thread workspace reused from call to call: repeated solves of
/// the same size (an update loop) allocate only the returned [`Modes`]. A dense [`System`] is
/// converted to band storage first (O(n²)); a banded one ([`System::banded`]) is used as it is.
///
/// ```
/// use eigenfit_core::eigen::{BandedSolver, DenseSolver, EigenSolver};
/// use eigenfit_core::matrix::{BandedSymmetric, System};
///
/// // A chain of 200 unit masses on unit springs, fixed at one end: K tridiagonal, M = I.
/// let n = 200;
/// let (mut k, mut m) = (BandedSymmetric::zeros(n, 1), BandedSymmetric::zeros(n, 0));
/// for i in 0..n {
///     m.add(i, i, 1.0);
///     k.add(i, i, if i + 1 < n { 2.0 } else { 1.0 });
///     if i + 1 < n {
///         k.add(i + 1, i, -1.0);
///     }
/// }
/// let system = System::banded(k, m)?;
/// let banded = BandedSolver::default().lowest(&system, 3)?;
/// let dense = DenseSolver.lowest(&system, 3)?;
/// for i in 0..3 {
///     assert!((banded.eigenvalues[i] / dense.eigenvalues[i] - 1.0).abs() < 1e-12);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandedSolver {
    /// Relative inverse-residual below which a mode is converged.
    pub tolerance: f64,
    /// Iterations allowed to the subspace-iteration fallback before the solve fails.
    pub max_iterations: usize,
}

impl Default for BandedSolver {
    fn default() -> Self {
        // 1e-12 on the shapes: a sensitivity φⱼ² at a stiff support, where φⱼ is small, then
        // agrees with the dense solver's to ~1e-12 (1e-10 left 6e-10 and costs 20 % less time on
        // the paper rotor). Eigenvalue-only solves need √ of it (see `request_tolerance`).
        Self { tolerance: 1e-12, max_iterations: 500 }
    }
}

/// Subspace size for `count` wanted modes of an n-DOF system: two guard vectors for a few modes
/// (cheap iterations, the spectrum of a beam spreads fast), up to 2m for many (fewer iterations).
pub fn subspace_size(dofs: usize, count: usize) -> usize {
    (count + 2).max((2 * count).min(count + 8)).min(dofs)
}

/// Reusable work arrays of one thread's solves.
#[derive(Default)]
struct Workspace {
    factor: BandCholesky,
    /// The last mass matrix proven positive definite: an update loop solves one M many times.
    checked_mass: Option<BandedSymmetric>,
    lanczos: LanczosWork,
    scratch: Vec<f64>,
    /// n×p blocks, row-major.
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    mz: Vec<f64>,
    /// p×p projected matrices and Ritz data, row-major.
    kr: Vec<f64>,
    mr: Vec<f64>,
    q: Vec<f64>,
    w: Vec<f64>,
    nu: Vec<f64>,
    scale: Vec<f64>,
    order: Vec<usize>,
}

impl Workspace {
    fn resize(&mut self, n: usize, p: usize) {
        for v in [&mut self.x, &mut self.y, &mut self.z, &mut self.mz] {
            v.clear();
            v.resize(n * p, 0.0);
        }
        for v in [&mut self.kr, &mut self.mr, &mut self.q, &mut self.w] {
            v.clear();
            v.resize(p * p, 0.0);
        }
        self.nu.clear();
        self.nu.resize(p, f64::INFINITY);
        self.scale.clear();
        self.scale.resize(p, 0.0);
    }
}

thread_local! {
    static WORKSPACE: RefCell<Workspace> = RefCell::new(Workspace::default());
}

impl EigenSolver for BandedSolver {
    fn name(&self) -> &'static str {
        "banded"
    }

    /// The next eigenvalue's bound is the Sturm check's shift: no eigenvalue beyond the modes
    /// returned lies below it, at no extra cost. Eigenvalues only are iterated less far
    /// (`request_tolerance`).
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError> {
        let banded = self.banded(system, request.count, request_tolerance(request, self.tolerance));
        match banded.map_err(|e| e.located(system))? {
            Some((modes, next)) => Ok(SolvedModes::answering(request, modes, next)),
            None => DenseSolver.solve(system, request),
        }
    }
}

impl BandedSolver {
    /// The lowest `count` modes with a lower bound on the next eigenvalue, or `None` for the
    /// dense solver: more than half the spectrum wanted, or a mode missed (see the type's
    /// documentation) in a system small enough for it.
    fn banded(
        &self,
        system: &System,
        count: usize,
        tolerance: f64,
    ) -> Result<Option<(Modes, f64)>, SolveError> {
        check_count(system, count)?;
        let n = system.dofs();
        if 2 * count > n {
            return Ok(None);
        }
        let converted;
        let (k, m) = match system.band() {
            Some(pair) => pair,
            None => {
                converted = (
                    BandedSymmetric::from_dense(system.stiffness()),
                    BandedSymmetric::from_dense(system.mass()),
                );
                (&converted.0, &converted.1)
            }
        };
        let found = WORKSPACE.with(|ws| {
            let ws = &mut *ws.try_borrow_mut().map_err(|_| backend("workspace in use (re-entrant solve)"))?;
            Self { tolerance, ..*self }.solve_band(k, m, count, ws)
        })?;
        match found {
            Some(found) => Ok(Some(found)),
            // The Sturm count found a mode below the highest one returned: the start vectors
            // missed it (or two eigenvalues coincide to 1e-6). The dense solver cannot miss modes.
            None if n <= MAX_DENSE_FALLBACK => Ok(None),
            None => Err(backend("a mode was missed by the subspace iteration (Sturm count)")),
        }
    }
}

/// Subspace iterations without halving the residual after which the iteration is abandoned.
const STALL_LIMIT: usize = 60;

/// The iteration behind a solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    /// Lanczos, falling back to subspace iteration when it does not converge.
    Lanczos,
    /// Block subspace iteration.
    Subspace,
}

/// Largest system the banded solver hands to the dense one when its Sturm check fails.
const MAX_DENSE_FALLBACK: usize = super::DENSE_MAX_DOFS;

fn well_conditioned(c: &BandCholesky) -> bool {
    let (dmin, dmax) = c.pivot_range();
    dmin > 1e-7 * dmax
}

fn backend(detail: impl Into<String>) -> SolveError {
    SolveError::Backend { backend: "banded", detail: detail.into() }
}

impl BandedSolver {
    /// The lowest `count` modes and a lower bound on the next eigenvalue, or `None` when the
    /// Sturm check shows a missed mode.
    fn solve_band(
        &self,
        k: &BandedSymmetric,
        m: &BandedSymmetric,
        count: usize,
        ws: &mut Workspace,
    ) -> Result<Option<(Modes, f64)>, SolveError> {
        if ws.checked_mass.as_ref() != Some(m) {
            if !ws.factor.factor_shifted(m, 0.0, m) {
                return Err(SolveError::MassNotPositiveDefinite { detail: None, dof: None });
            }
            ws.checked_mass = Some(m.clone());
        }
        let modes = match self.modes(k, m, count, Method::Lanczos, ws) {
            Ok(modes) => modes,
            // The iterations failed (an extreme stiffness contrast): the dense solver decides,
            // where it can, and reports input faults (negative stiffness) in its own words.
            Err(_) if m.dim() <= MAX_DENSE_FALLBACK => return Ok(None),
            Err(e) => return Err(e),
        };
        if let Some(next) = sturm_bound(k, m, &modes, &mut ws.scratch) {
            return Ok(Some((modes, next)));
        }
        // Lanczos missed a mode (one start vector sees a repeated eigenvalue once): a block of p
        // vectors sees multiplicities up to p − m. Its failure, too, ends in `None`.
        let Ok(modes) = self.modes(k, m, count, Method::Subspace, ws) else {
            return Ok(None);
        };
        Ok(sturm_bound(k, m, &modes, &mut ws.scratch).map(|next| (modes, next)))
    }

    /// The lowest `count` modes by `method`, with the dense solver's shift strategy.
    fn modes(
        &self,
        k: &BandedSymmetric,
        m: &BandedSymmetric,
        count: usize,
        method: Method,
        ws: &mut Workspace,
    ) -> Result<Modes, SolveError> {
        if ws.factor.factor_shifted(k, 0.0, m) && well_conditioned(&ws.factor) {
            return self.iterate(m, 0.0, count, method, ws);
        }
        // Rigid-body modes: the dense solver's two shifts.
        let scale = k.diagonal_max() / m.diagonal_max();
        shifted_twice(scale, |sigma| {
            if !ws.factor.factor_shifted(k, sigma, m) {
                return Err(backend("K + σM is not positive definite: K has negative stiffness"));
            }
            self.iterate(m, sigma, count, method, ws)
        })
    }

    /// The lowest modes from the factor of K + σM held in the workspace: by Lanczos unless told
    /// otherwise, by block subspace iteration when Lanczos does not converge in its step limit.
    fn iterate(
        &self,
        m: &BandedSymmetric,
        sigma: f64,
        count: usize,
        method: Method,
        ws: &mut Workspace,
    ) -> Result<Modes, SolveError> {
        let lanczos = match method {
            Method::Lanczos => {
                lanczos::largest(&mut ws.factor, m, count, self.tolerance, None, &mut ws.lanczos)
            }
            Method::Subspace => None,
        };
        if let Some(ritz) = lanczos {
            let n = m.dim();
            let eigenvalues = DVector::from_iterator(count, ritz.mu.iter().map(|&mu| 1.0 / mu - sigma));
            // Refined eigenvalues out of order mean the Ritz vectors were not what the residual
            // estimate claimed (an extreme stiffness contrast): the block iteration takes over.
            if ascending(&eigenvalues) {
                let shapes = DMatrix::from_column_slice(n, count, ritz.vectors);
                return finish(eigenvalues, shapes);
            }
        }
        self.subspace_iteration(m, sigma, count, ws)
    }

    /// Block subspace iteration with the factor of K + σM held in the workspace.
    fn subspace_iteration(
        &self,
        m: &BandedSymmetric,
        sigma: f64,
        count: usize,
        ws: &mut Workspace,
    ) -> Result<Modes, SolveError> {
        let n = m.dim();
        let p = subspace_size(n, count);
        ws.resize(n, p);
        start_vectors(&mut ws.x, 0);
        m.mul_block(&ws.x, &mut ws.y, p);
        let (mut best, mut stalled, mut refills, mut first) = (f64::INFINITY, 0, 0, true);
        for _ in 0..self.max_iterations {
            ws.z.copy_from_slice(&ws.y);
            ws.factor.solve_block(&mut ws.z, p);
            if !first {
                let res = inverse_residual(&ws.x, &ws.z, &ws.nu, p, count);
                // Converged, or at the round-off floor: no more progress on a small residual.
                // "No halving in 4 iterations" is also what slow steady convergence looks like
                // (a cluster beyond the subspace: 5 % per iteration, shapes 1e-6 off at 1e-6);
                // a system the dense solver can take goes there instead of taking that answer.
                let floor = stalled >= 4 && best <= 1e-6;
                if floor && res > self.tolerance && n <= MAX_DENSE_FALLBACK {
                    return Err(backend(format!("subspace iteration slowed down at residual {best:.1e}")));
                }
                if res <= self.tolerance || floor {
                    let eigenvalues = DVector::from_iterator(count, ws.nu[..count].iter().map(|v| v - sigma));
                    if !ascending(&eigenvalues) {
                        return Err(backend("subspace iteration returned eigenvalues out of order"));
                    }
                    let shapes = DMatrix::from_fn(n, count, |r, c| ws.x[r * p + c]);
                    return finish(eigenvalues, shapes);
                }
                if res < 0.5 * best {
                    best = res;
                    stalled = 0;
                } else {
                    stalled += 1;
                }
                // No halving of the residual in this many iterations is not slow convergence but
                // none (an ill-conditioned mesh): fail now rather than after `max_iterations`.
                if stalled >= STALL_LIMIT {
                    return Err(backend(format!(
                        "subspace iteration made no progress in {STALL_LIMIT} iterations (residual {best:.1e})"
                    )));
                }
            }
            first = false;
            gram(&ws.z, &ws.y, &mut ws.kr, p);
            m.mul_block(&ws.z, &mut ws.mz, p);
            gram(&ws.z, &ws.mz, &mut ws.mr, p);
            projected(ws, p)?;
            // X = ZQ and, since M is linear, MX = (MZ)Q without another band product.
            combine(&ws.z, &ws.q, &mut ws.x, p);
            combine(&ws.mz, &ws.q, &mut ws.y, p);
            let lost: Vec<usize> = (0..p).filter(|&j| !ws.nu[j].is_finite()).collect();
            if !lost.is_empty() {
                for j in lost {
                    refills += 1;
                    refill_column(&mut ws.x, p, j, refills);
                }
                m.mul_block(&ws.x, &mut ws.y, p);
            }
        }
        Err(backend(format!("subspace iteration did not converge in {} iterations", self.max_iterations)))
    }
}

/// Sturm check: exactly `count` eigenvalues lie below a point σ′ just above the highest one
/// found. Returns σ′ — a lower bound on the next eigenvalue — or `None` when a mode was missed;
/// the highest one itself when the extra eigenvalues below σ′ are all copies of it (a second
/// count just below it finds nothing missed).
fn sturm_bound(
    k: &BandedSymmetric,
    m: &BandedSymmetric,
    modes: &Modes,
    scratch: &mut Vec<f64>,
) -> Option<f64> {
    let count = modes.count();
    let top = modes.eigenvalues[count - 1];
    // Above round-off of a rigid-body zero, and 1e-6 relative above an elastic eigenvalue.
    let floor = 1e-11 * k.diagonal_max() / m.diagonal_max();
    let margin = (1e-6 * top.abs()).max(floor);
    let sigma = top + margin;
    match k.count_below(m, sigma, scratch)? {
        below if below == count => Some(sigma),
        // More below σ than found: when a count just below `top` finds only the modes found
        // there, the rest are copies of `top` (an eigenvalue of high multiplicity, K = cI), not
        // missed modes; the next eigenvalue is one of them (the sparse solver's rule).
        below if below > count => {
            let low = top - margin;
            let known_low = modes.eigenvalues.iter().filter(|&&l| l < low).count();
            (k.count_below(m, low, scratch)? == known_low).then_some(top)
        }
        _ => None,
    }
}

/// max over the wanted modes of ‖νᵢ zᵢ − xᵢ‖∞ / ‖xᵢ‖∞ (blocks row-major, p columns).
fn inverse_residual(x: &[f64], z: &[f64], nu: &[f64], p: usize, count: usize) -> f64 {
    if nu[..count].iter().any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    let mut worst = 0.0_f64;
    for i in 0..count {
        let (mut scale, mut diff) = (0.0_f64, 0.0_f64);
        for (xr, zr) in x.chunks_exact(p).zip(z.chunks_exact(p)) {
            scale = scale.max(xr[i].abs());
            diff = diff.max((nu[i] * zr[i] - xr[i]).abs());
        }
        worst = worst.max(if scale > 0.0 { diff / scale } else { f64::INFINITY });
    }
    worst
}

/// out = AᵀB for row-major n×p blocks A, B (p×p, row-major).
fn gram(a: &[f64], b: &[f64], out: &mut [f64], p: usize) {
    out.fill(0.0);
    for (ar, br) in a.chunks_exact(p).zip(b.chunks_exact(p)) {
        for (i, &ai) in ar.iter().enumerate() {
            for (o, &bj) in out[i * p..(i + 1) * p].iter_mut().zip(br) {
                *o += ai * bj;
            }
        }
    }
}

/// out = A Q for a row-major n×p block A and p×p Q.
fn combine(a: &[f64], q: &[f64], out: &mut [f64], p: usize) {
    for (ar, or) in a.chunks_exact(p).zip(out.chunks_exact_mut(p)) {
        or.fill(0.0);
        for (i, &ai) in ar.iter().enumerate() {
            for (o, &qj) in or.iter_mut().zip(&q[i * p..(i + 1) * p]) {
                *o += ai * qj;
            }
        }
    }
}

/// Rayleigh–Ritz on the pencil Kr q = ν Mr q (p×p in the workspace, both positive definite), in
/// inverted form: ν ascending into `ws.nu` and Q (QᵀMrQ = I) into `ws.q`. A direction lost to
/// round-off (the columns of Z nearly dependent, as after the first step from random vectors when
/// λ₂/λ₁ is huge) comes back as ν = ∞ with a zero column in Q, for the caller to refill.
fn projected(ws: &mut Workspace, p: usize) -> Result<(), SolveError> {
    let Workspace { kr, mr, q, w, nu, scale, order, .. } = ws;
    // Jacobi scaling: the columns of Z differ in size by λ_p/λ_1.
    for i in 0..p {
        scale[i] = 1.0 / mr[i * p + i].max(f64::MIN_POSITIVE).sqrt();
    }
    for i in 0..p {
        for j in 0..=i {
            let s = scale[i] * scale[j];
            let (kv, mv) =
                (0.5 * (kr[i * p + j] + kr[j * p + i]) * s, 0.5 * (mr[i * p + j] + mr[j * p + i]) * s);
            kr[i * p + j] = kv;
            kr[j * p + i] = kv;
            mr[i * p + j] = mv;
            mr[j * p + i] = mv;
        }
    }
    // Kr = LLᵀ in place (lower triangle).
    for j in 0..p {
        let mut d = kr[j * p + j];
        for k in 0..j {
            d -= kr[j * p + k] * kr[j * p + k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(backend("projected stiffness is not positive definite"));
        }
        let d = d.sqrt();
        kr[j * p + j] = d;
        for i in j + 1..p {
            let mut s = kr[i * p + j];
            for k in 0..j {
                s -= kr[i * p + k] * kr[j * p + k];
            }
            kr[i * p + j] = s / d;
        }
    }
    // A = L⁻¹ Mr L⁻ᵀ: rows of L⁻¹Mr by forward substitution, then the same on its transpose.
    for _ in 0..2 {
        for c in 0..p {
            for i in 0..p {
                let mut s = mr[i * p + c];
                for k in 0..i {
                    s -= kr[i * p + k] * mr[k * p + c];
                }
                mr[i * p + c] = s / kr[i * p + i];
            }
        }
        transpose_in_place(mr, p);
    }
    for i in 0..p {
        for j in 0..i {
            let v = 0.5 * (mr[i * p + j] + mr[j * p + i]);
            mr[i * p + j] = v;
            mr[j * p + i] = v;
        }
    }
    if !symmetric_eigen(mr, w, p) {
        return Err(backend("projected Jacobi iteration did not converge"));
    }
    order.clear();
    order.extend(0..p);
    order.sort_by(|&i, &j| mr[j * p + j].total_cmp(&mr[i * p + i]));
    let mu_max = mr[order[0] * p + order[0]];
    if mu_max.is_nan() || mu_max <= 0.0 {
        return Err(backend("the iteration subspace collapsed"));
    }
    // Q = D L⁻ᵀ W Λ^(-1/2), columns in ascending ν.
    for (col, &i) in order.iter().enumerate() {
        let mu = mr[i * p + i];
        let good = mu > 1e-14 * mu_max;
        nu[col] = if good { 1.0 / mu } else { f64::INFINITY };
        let f = if good { 1.0 / mu.sqrt() } else { 0.0 };
        for r in (0..p).rev() {
            let mut s = w[r * p + i] * f;
            for k in r + 1..p {
                s -= kr[k * p + r] * q[k * p + col];
            }
            q[r * p + col] = s / kr[r * p + r];
        }
    }
    for r in 0..p {
        for v in &mut q[r * p..(r + 1) * p] {
            *v *= scale[r];
        }
    }
    Ok(())
}

fn transpose_in_place(a: &mut [f64], p: usize) {
    for i in 0..p {
        for j in 0..i {
            a.swap(i * p + j, j * p + i);
        }
    }
}

/// Deterministic pseudo-random start block, so solves are reproducible.
fn start_vectors(x: &mut [f64], offset: u64) {
    for (k, v) in x.iter_mut().enumerate() {
        *v = pseudo_random(offset + k as u64);
    }
}

/// A fresh pseudo-random column j (the `refill`-th) in place of a lost direction.
fn refill_column(x: &mut [f64], p: usize, j: usize, refill: usize) {
    let n = x.len() / p;
    for (r, row) in x.chunks_exact_mut(p).enumerate() {
        row[j] = pseudo_random(((refill * n + r) as u64) << 20);
    }
}

/// Non-decreasing up to round-off (1e-12 relative).
fn ascending(values: &DVector<f64>) -> bool {
    values.as_slice().windows(2).all(|w| w[1] >= w[0] - 1e-12 * w[0].abs())
}

/// Rejects non-finite results and applies the sign rule.
fn finish(eigenvalues: DVector<f64>, mut shapes: DMatrix<f64>) -> Result<Modes, SolveError> {
    if eigenvalues.iter().chain(shapes.iter()).any(|v| !v.is_finite()) {
        return Err(backend("non-finite result"));
    }
    apply_sign_rule(&mut shapes);
    Ok(Modes { eigenvalues, shapes })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed–free chain of `n` masses: K tridiagonal, M diagonal, band storage.
    fn chain(n: usize, ground: f64) -> System {
        let mut k = BandedSymmetric::zeros(n, 1);
        let mut m = BandedSymmetric::zeros(n, 0);
        for i in 0..n {
            m.add(i, i, 1.0 + 0.3 * ((i * 7) % 5) as f64);
            if i + 1 < n {
                let s = 100.0 + (i % 3) as f64;
                k.add(i, i, s);
                k.add(i + 1, i + 1, s);
                k.add(i + 1, i, -s);
            }
        }
        k.add(0, 0, ground);
        System::banded(k, m).unwrap()
    }

    fn assert_agrees(a: &Modes, b: &Modes, tol: f64) {
        for k in 0..a.count() {
            let rel = (a.eigenvalues[k] - b.eigenvalues[k]).abs() / b.eigenvalues[k].abs().max(1e-300);
            assert!(rel < tol, "mode {k}: {} vs {}", a.eigenvalues[k], b.eigenvalues[k]);
            let (x, y) = (a.shapes.column(k), b.shapes.column(k));
            let d = (x - y).amax().min((x + y).amax());
            assert!(d < 1e-6 * y.amax(), "mode {k} shape differs by {d}");
        }
    }

    #[test]
    fn agrees_with_dense_on_a_chain() {
        let sys = chain(200, 50.0);
        for count in [1, 5, 12] {
            let a = BandedSolver::default().lowest(&sys, count).unwrap();
            let b = DenseSolver.lowest(&sys, count).unwrap();
            assert_agrees(&a, &b, 1e-9);
            let phi = &a.shapes;
            let mtm = phi.transpose() * sys.mass() * phi;
            assert!((mtm - DMatrix::identity(count, count)).amax() < 1e-10);
        }
    }

    #[test]
    fn free_chain_has_a_rigid_body_mode() {
        let sys = chain(120, 0.0);
        let a = BandedSolver::default().lowest(&sys, 4).unwrap();
        let b = DenseSolver.lowest(&sys, 4).unwrap();
        assert!(a.eigenvalues[0].abs() < 1e-9 * a.eigenvalues[1]);
        assert_agrees(
            &Modes { eigenvalues: a.eigenvalues.rows(1, 3).into(), shapes: a.shapes.columns(1, 3).into() },
            &Modes { eigenvalues: b.eigenvalues.rows(1, 3).into(), shapes: b.shapes.columns(1, 3).into() },
            1e-9,
        );
    }

    #[test]
    fn small_and_dense_systems_and_bad_input() {
        let small = chain(10, 1.0);
        assert_agrees(
            &BandedSolver::default().lowest(&small, 2).unwrap(),
            &DenseSolver.lowest(&small, 2).unwrap(),
            1e-12,
        );
        // More than half the spectrum: the dense solver's job.
        assert_eq!(BandedSolver::default().lowest(&small, 6), DenseSolver.lowest(&small, 6));
        let dense = System::new(chain(90, 5.0).stiffness().clone(), chain(90, 5.0).mass().clone()).unwrap();
        let a = BandedSolver::default().lowest(&dense, 3).unwrap();
        assert_agrees(&a, &DenseSolver.lowest(&dense, 3).unwrap(), 1e-9);
        let (k, _) = chain(90, 5.0).into_parts();
        let neg = System::new(k, DMatrix::from_diagonal_element(90, 90, -1.0)).unwrap();
        assert!(matches!(
            BandedSolver::default().lowest(&neg, 2),
            Err(SolveError::MassNotPositiveDefinite { .. })
        ));
        assert_eq!(BandedSolver::default().lowest(&dense, 0), Err(SolveError::NoModes));
    }

    #[test]
    fn sturm_count_catches_a_missed_mode() {
        let sys = chain(60, 3.0);
        let (k, m) = sys.band().unwrap();
        let all = DenseSolver.lowest(&sys, 4).unwrap();
        let mut scratch = Vec::new();
        assert!(sturm_bound(k, m, &all, &mut scratch)
            .is_some_and(|b| b < DenseSolver.lowest(&sys, 5).unwrap().eigenvalues[4]));
        // Modes 0, 1, 3 without 2: a subspace iteration that missed a mode would return this.
        let keep = [0, 1, 3];
        let missed = Modes {
            eigenvalues: DVector::from_iterator(3, keep.iter().map(|&i| all.eigenvalues[i])),
            shapes: DMatrix::from_columns(&keep.map(|i| all.shapes.column(i))),
        };
        assert_eq!(sturm_bound(k, m, &missed, &mut scratch), None);
        for (sigma, below) in [(0.0, 0), (0.5 * (all.eigenvalues[1] + all.eigenvalues[2]), 2)] {
            assert_eq!(k.count_below(m, sigma, &mut scratch), Some(below));
        }
    }
}
