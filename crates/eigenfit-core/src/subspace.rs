//! The large-model eigen-solver: shift-invert subspace iteration on a banded Cholesky factor.

use crate::banded::{BandCholesky, BandedSymmetric};
use crate::dense::DenseSolver;
use crate::modes::{apply_sign_rule, Modes};
use crate::solver::{check_count, EigenSolver, SolveError};
use crate::system::System;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Lowest modes of large banded systems (beam meshes of 10³–10⁵ DOFs) in O(n·m²) per iteration.
///
/// Subspace iteration (Bathe) with the inverted operator: K + σM = LLᵀ is factored once by band
/// (O(n·b²), b = 3 for beam models), then a block of p = max(2m, m + 8) M-orthonormal vectors X
/// is driven towards the lowest modes by Z = (K + σM)⁻¹MX followed by a Rayleigh–Ritz step on
/// span(Z). The projected p×p problem is solved in the same inverted form as [`DenseSolver`]
/// (eigenvalues μ = 1/(λ + σ) of the pencil (ZᵀMZ, ZᵀK_σZ)), so a low mode keeps round-off
/// relative to its own eigenvalue rather than to λ_max. The shift follows the dense solver: σ = 0
/// when K is positive definite, otherwise a tiny σ₀ and then the lowest elastic eigenvalue.
///
/// A mode counts as converged when its inverse residual ‖ν zᵢ − xᵢ‖∞ / ‖xᵢ‖∞ (ν = λ + σ) falls
/// below [`tolerance`](Self::tolerance): that is the relative error of the mode shape; the
/// eigenvalue's is about its square. Systems too small for the iteration to pay (n < 3p) are
/// handed to [`DenseSolver`]. A dense [`System`] is converted to band storage first (O(n²));
/// a banded one ([`System::banded`]) is used as it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandedSolver {
    /// Relative inverse-residual below which a mode is converged.
    pub tolerance: f64,
    /// Subspace iterations allowed before the solve fails.
    pub max_iterations: usize,
}

impl Default for BandedSolver {
    fn default() -> Self {
        // 1e-8 on the shapes (1e-16 on the eigenvalues) is at the round-off floor of fine beam
        // meshes already; asking for less only spends iterations until the stall rule stops them.
        Self { tolerance: 1e-8, max_iterations: 500 }
    }
}

/// Subspace size for `count` wanted modes of an n-DOF system.
pub fn subspace_size(dofs: usize, count: usize) -> usize {
    (2 * count).max(count + 8).min(dofs)
}

impl EigenSolver for BandedSolver {
    fn name(&self) -> &'static str {
        "banded"
    }

    fn lowest(&self, system: &System, count: usize) -> Result<Modes, SolveError> {
        check_count(system, count)?;
        let n = system.dofs();
        let p = subspace_size(n, count);
        if 3 * p > n {
            return DenseSolver.lowest(system, count);
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
        if m.cholesky().is_none() {
            return Err(SolveError::MassNotPositiveDefinite { detail: None });
        }
        if let Some(chol) = k.cholesky().filter(well_conditioned) {
            return self.iterate(&chol, m, 0.0, count, p);
        }
        // Rigid-body modes: as in the dense solver, locate the lowest elastic mode with a tiny
        // shift, then shift to it for accuracy.
        let scale = k.diagonal_max() / m.diagonal_max();
        let sigma0 = 1e-8 * scale.max(f64::MIN_POSITIVE);
        let first = self.shifted(k, m, sigma0, count, p)?;
        match first.eigenvalues.iter().find(|&&l| l > 1e-3 * sigma0) {
            Some(&sigma1) if sigma1 > 10.0 * sigma0 => self.shifted(k, m, sigma1, count, p),
            _ => Ok(first),
        }
    }
}

fn well_conditioned(c: &BandCholesky) -> bool {
    let (dmin, dmax) = c.pivot_range();
    dmin > 1e-7 * dmax
}

fn backend(detail: impl Into<String>) -> SolveError {
    SolveError::Backend { backend: "banded", detail: detail.into() }
}

impl BandedSolver {
    fn shifted(
        &self,
        k: &BandedSymmetric,
        m: &BandedSymmetric,
        sigma: f64,
        count: usize,
        p: usize,
    ) -> Result<Modes, SolveError> {
        let chol = k
            .add_scaled(sigma, m)
            .cholesky()
            .ok_or_else(|| backend("K + σM is not positive definite: K has negative stiffness"))?;
        self.iterate(&chol, m, sigma, count, p)
    }

    /// Subspace iteration with the factor of K + σM; returns the lowest `count` modes.
    fn iterate(
        &self,
        chol: &BandCholesky,
        m: &BandedSymmetric,
        sigma: f64,
        count: usize,
        p: usize,
    ) -> Result<Modes, SolveError> {
        let n = m.dim();
        let mut x = start_vectors(n, p);
        let mut y = DMatrix::zeros(n, p);
        let mut z = DMatrix::zeros(n, p);
        let mut mz = DMatrix::zeros(n, p);
        let mut kr = DMatrix::zeros(p, p);
        let mut mr = DMatrix::zeros(p, p);
        let mut nu: Option<DVector<f64>> = None;
        let (mut best, mut stalled, mut refills) = (f64::INFINITY, 0, 0);
        m.mul_columns(&x, &mut y);
        for _ in 0..self.max_iterations {
            z.copy_from(&y);
            chol.solve_columns(&mut z);
            if let Some(nu) = &nu {
                let res = inverse_residual(&x, &z, nu, count);
                // Converged, or at the round-off floor: no more progress on a small residual.
                if res <= self.tolerance || (stalled >= 4 && best <= 1e-6) {
                    let eigenvalues = DVector::from_iterator(count, nu.iter().take(count).map(|v| v - sigma));
                    let shapes = x.columns(0, count).into_owned();
                    return finish(eigenvalues, shapes);
                }
                if res < 0.5 * best {
                    best = res;
                    stalled = 0;
                } else {
                    stalled += 1;
                }
            }
            kr.gemm_tr(1.0, &z, &y, 0.0);
            m.mul_columns(&z, &mut mz);
            mr.gemm_tr(1.0, &z, &mz, 0.0);
            let (values, q) = projected(&kr, &mr)?;
            x.gemm(1.0, &z, &q, 0.0);
            for j in (0..p).filter(|&j| !values[j].is_finite()) {
                refills += 1;
                x.column_mut(j).copy_from(&start_vectors(n, 1 + refills).column(refills));
            }
            m.mul_columns(&x, &mut y);
            nu = Some(values);
        }
        Err(backend(format!("subspace iteration did not converge in {} iterations", self.max_iterations)))
    }
}

/// max over the wanted modes of ‖νᵢ zᵢ − xᵢ‖∞ / ‖xᵢ‖∞.
fn inverse_residual(x: &DMatrix<f64>, z: &DMatrix<f64>, nu: &DVector<f64>, count: usize) -> f64 {
    if nu.iter().take(count).any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    (0..count)
        .map(|i| {
            let (xc, zc) = (x.column(i), z.column(i));
            let scale = xc.amax();
            let diff = xc.iter().zip(zc.iter()).fold(0.0_f64, |a, (xv, zv)| a.max((nu[i] * zv - xv).abs()));
            if scale > 0.0 {
                diff / scale
            } else {
                f64::INFINITY
            }
        })
        .fold(0.0, f64::max)
}

/// Rayleigh–Ritz on the pencil Kr q = ν Mr q (both p×p, positive definite), in inverted form:
/// ν ascending and Q with QᵀMrQ = I.
fn projected(kr: &DMatrix<f64>, mr: &DMatrix<f64>) -> Result<(DVector<f64>, DMatrix<f64>), SolveError> {
    let p = kr.nrows();
    // Jacobi scaling: the columns of Z differ in size by λ_p/λ_1.
    let d = DVector::from_iterator(p, (0..p).map(|i| 1.0 / mr[(i, i)].max(f64::MIN_POSITIVE).sqrt()));
    let scale = |a: &DMatrix<f64>| DMatrix::from_fn(p, p, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]) * d[i] * d[j]);
    let (ks, ms) = (scale(kr), scale(mr));
    let c = ks.cholesky().ok_or_else(|| backend("projected stiffness is not positive definite"))?;
    let l = c.l();
    let t = l.solve_lower_triangular(&ms).ok_or_else(|| backend("zero pivot in projected factor"))?;
    let a =
        l.solve_lower_triangular(&t.transpose()).ok_or_else(|| backend("zero pivot in projected factor"))?;
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::try_new(a, f64::EPSILON, 0)
        .ok_or_else(|| backend("projected symmetric QR iteration did not converge"))?;
    let mut order: Vec<usize> = (0..p).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let mu_max = eig.eigenvalues[order[0]];
    if mu_max.is_nan() || mu_max <= 0.0 {
        return Err(backend("the iteration subspace collapsed"));
    }
    // Directions lost to round-off (the columns of Z nearly dependent, as after the first step
    // from random vectors when λ₂/λ₁ is huge) come back as ν = ∞ with a zero column in Q; the
    // caller refills them.
    let good = |i: usize| eig.eigenvalues[i] > 1e-14 * mu_max;
    let values = DVector::from_iterator(
        p,
        order.iter().map(|&i| if good(i) { 1.0 / eig.eigenvalues[i] } else { f64::INFINITY }),
    );
    let w = DMatrix::from_fn(p, p, |r, j| {
        let i = order[j];
        if good(i) {
            eig.eigenvectors[(r, i)] / eig.eigenvalues[i].sqrt()
        } else {
            0.0
        }
    });
    let mut q =
        l.transpose().solve_upper_triangular(&w).ok_or_else(|| backend("zero pivot in projected factor"))?;
    for (i, mut row) in q.row_iter_mut().enumerate() {
        row *= d[i];
    }
    Ok((values, q))
}

/// Deterministic pseudo-random start block (splitmix64), so solves are reproducible.
fn start_vectors(n: usize, p: usize) -> DMatrix<f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    DMatrix::from_fn(n, p, |_, _| {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    })
}

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
        assert_eq!(BandedSolver::default().lowest(&small, 2), DenseSolver.lowest(&small, 2));
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
}
