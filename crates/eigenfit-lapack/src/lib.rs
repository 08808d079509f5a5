//! # eigenfit-lapack
//!
//! A LAPACK implementation of [`EigenSolver`] for the generalized symmetric-definite problem
//! K φ = λ M φ, linked against the system OpenBLAS (Debian/Ubuntu: `libopenblas-dev`).
//!
//! [`LapackSolver`] uses one of two LAPACK drivers, chosen by [`Method`]:
//!
//! * `dsygvd` ([`Method::All`]): Cholesky reduction, tridiagonalisation and divide-and-conquer
//!   for the whole spectrum; the fastest way to get all or most modes.
//! * `dsygvx` ([`Method::Subset`]): the same reduction, then bisection and inverse iteration for
//!   the modes `1..=count` only; cheaper when a few of many modes are wanted.
//!
//! [`Method::Auto`] (the default) uses `dsygvx` when `4·count < n` and `dsygvd` otherwise.
//!
//! The result follows the convention of every eigenfit backend (see [`DenseSolver`]):
//! eigenvalues ascending, mode shapes mass-normalised (ΦᵀMΦ = I), [`apply_sign_rule`] applied.
//!
//! Accuracy: like [`DenseSolver`], for at most half the modes both drivers solve the inverted
//! problem M x = μ (K + σM) x (μ = 1/(λ + σ); σ = 0 unless K is singular or nearly so), so the
//! lowest modes keep round-off relative to their own eigenvalues rather than to λ_max; for more
//! than half they reduce with the Cholesky factor of M (eigenvalue j then carries an absolute
//! error of about ε·λ_max, which keeps the whole basis M-orthonormal). On a stiff cantilever
//! (λ_max/λ₁ ≈ 5e11 at 402 DOFs) the lowest five eigenvalues agree with the dense solver's to
//! 1.8e-9 relative (test `low_modes_of_a_stiff_cantilever_agree_relative_to_themselves`; 4e-6 with
//! the textbook reduction): `dsygst`'s two-sided reduction with the factor of an ill-conditioned
//! K loses more than the dense solver's triangular solves, which agree with the banded solver to
//! 1e-14.
//!
//! ```
//! use eigenfit_core::eigen::EigenSolver;
//! use eigenfit_core::matrix::System;
//! use eigenfit_lapack::LapackSolver;
//! use nalgebra::DMatrix;
//!
//! // Two masses on springs: K = [[2,-1],[-1,2]], M = I  →  λ = 1, 3.
//! let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 2.0]);
//! let m = DMatrix::identity(2, 2);
//! let modes = LapackSolver::default().lowest(&System::new(k, m)?, 2)?;
//! assert!((modes.eigenvalues[0] - 1.0).abs() < 1e-12);
//! assert!((modes.eigenvalues[1] - 3.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`DenseSolver`]: eigenfit_core::eigen::DenseSolver
//! [`apply_sign_rule`]: eigenfit_core::eigen::apply_sign_rule

#![warn(missing_docs)]

// Links the system OpenBLAS, which provides the LAPACK symbols the `lapack` crate declares.
extern crate openblas_src;

mod driver;

use eigenfit_core::eigen::{
    apply_sign_rule, check_count, shifted_twice, with_next_by_one_more_mode, EigenSolver, ModeRequest, Modes,
    SolveError, SolvedModes,
};
use eigenfit_core::matrix::System;
use nalgebra::{DMatrix, DVector};

/// Backend name reported by [`LapackSolver`] and used in [`SolveError::Backend`].
pub const BACKEND: &str = "lapack";

/// Which LAPACK driver [`LapackSolver`] uses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// [`Method::Subset`] when `4·count < n`, otherwise [`Method::All`].
    #[default]
    Auto,
    /// `dsygvd`: every eigenpair by divide and conquer, then the lowest `count` are kept.
    /// Workspace O(n²).
    All,
    /// `dsygvx` with `RANGE = 'I'`: only eigenpairs `1..=count`, by bisection (with the most
    /// accurate tolerance, `ABSTOL = 2·dlamch('S')`) and inverse iteration. Workspace O(n·count).
    Subset,
}

impl Method {
    /// The driver actually used for `count` of `dofs` modes: [`Method::All`] or
    /// [`Method::Subset`], never [`Method::Auto`].
    ///
    /// ```
    /// use eigenfit_lapack::Method;
    ///
    /// assert_eq!(Method::Auto.resolve(400, 10), Method::Subset);
    /// assert_eq!(Method::Auto.resolve(400, 100), Method::All);
    /// assert_eq!(Method::All.resolve(400, 10), Method::All);
    /// ```
    pub fn resolve(self, dofs: usize, count: usize) -> Method {
        match self {
            Method::Auto if count.saturating_mul(4) < dofs => Method::Subset,
            Method::Auto => Method::All,
            other => other,
        }
    }
}

/// LAPACK (OpenBLAS) eigen-solver: `dsygvd` or `dsygvx` according to [`Method`].
///
/// Errors: [`SolveError::MassNotPositiveDefinite`] (naming the leading minor of M at which the
/// Cholesky factorisation failed), [`SolveError::TooManyModes`] / [`SolveError::NoModes`] for a
/// bad `count`, and [`SolveError::Backend`] with backend `"lapack"` for anything else (no
/// convergence, non-finite results, a system too large for LAPACK's 32-bit integers).
///
/// ```
/// use eigenfit_core::eigen::{EigenSolver, SolveError};
/// use eigenfit_core::matrix::System;
/// use eigenfit_lapack::{LapackSolver, Method};
/// use nalgebra::DMatrix;
///
/// // A fixed–fixed chain of 40 unit masses and unit springs; the lowest three modes.
/// let n = 40;
/// let k = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
///     0 => 2.0,
///     1 => -1.0,
///     _ => 0.0,
/// });
/// let system = System::new(k, DMatrix::identity(n, n))?;
/// let subset = LapackSolver::new(Method::Subset).lowest(&system, 3)?;
/// let all = LapackSolver::new(Method::All).lowest(&system, 3)?;
/// for j in 0..3 {
///     // λⱼ = 4 sin²(jπ / 2(n+1))
///     let s = ((j + 1) as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin();
///     assert!((subset.eigenvalues[j] - 4.0 * s * s).abs() < 1e-13);
///     assert!((all.eigenvalues[j] - subset.eigenvalues[j]).abs() < 1e-13);
/// }
///
/// // A massless degree of freedom is reported, not a panic.
/// let mut m = DMatrix::identity(n, n);
/// m[(5, 5)] = 0.0;
/// let err = LapackSolver::default().lowest(&System::new(DMatrix::identity(n, n), m)?, 3);
/// assert!(matches!(err, Err(SolveError::MassNotPositiveDefinite { detail: Some(_), .. })));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct LapackSolver {
    /// Driver selection; [`Method::Auto`] by default.
    pub method: Method,
}

impl LapackSolver {
    /// A solver using `method`.
    pub const fn new(method: Method) -> Self {
        Self { method }
    }
}

impl EigenSolver for LapackSolver {
    fn name(&self) -> &'static str {
        BACKEND
    }

    /// Its certificate is the next eigenvalue itself, from a solve of one mode more; eigenvalues
    /// only are the full solve's.
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError> {
        with_next_by_one_more_mode(system, request, |count, _| {
            check_count(system, count)?;
            let n = system.dofs();
            solve(system.stiffness(), system.mass(), count, self.method.resolve(n, count))
        })
    }
}

/// The lowest `count` modes of (K, M) with the given driver (`All` or `Subset`).
///
/// Like [`DenseSolver`](eigenfit_core::eigen::DenseSolver): for at most half the modes, the inverted
/// problem M x = μ (K + σM) x (μ = 1/(λ + σ), the lowest modes the largest μ), so each low mode
/// keeps round-off relative to its own eigenvalue; σ = 0 when K is well-conditioned positive
/// definite, else the shared two-shift strategy. For more than half, the textbook reduction with
/// M's factor, which keeps the whole basis M-orthonormal.
fn solve(k: &DMatrix<f64>, m: &DMatrix<f64>, count: usize, method: Method) -> Result<Modes, SolveError> {
    // `System::new` rejects non-finite entries; a NaN must never reach LAPACK regardless.
    if k.iter().chain(m.iter()).any(|v| !v.is_finite()) {
        return Err(backend("K or M has a non-finite entry".into()));
    }
    let n = k.nrows();
    if 2 * count > n {
        let (values, vectors) = pairs(k, m, 0, count, n, method)?;
        return finish(values.iter().map(|&l| (l, 1.0)).collect(), &vectors, n);
    }
    if let Err(order) = driver::cholesky_pivots(n, m.as_slice())? {
        return Err(SolveError::MassNotPositiveDefinite {
            detail: Some(format!(
                "the leading minor of order {order} of M is not positive definite (dpotrf)"
            )),
            dof: order.checked_sub(1),
        });
    }
    let inverted = |sigma: f64| {
        let shifted = if sigma == 0.0 { k.clone() } else { k + m * sigma };
        // The largest `count` μ of M x = μ (K + σM) x, ascending.
        let (mu, vectors) = pairs(m, &shifted, n - count, count, n, method).map_err(|e| match e {
            SolveError::MassNotPositiveDefinite { .. } => {
                backend("K + σM is not positive definite: K has negative stiffness".into())
            }
            other => other,
        })?;
        if mu.iter().any(|&v| v <= 0.0 || v.is_nan()) {
            return Err(backend("a reduced eigenvalue is not positive".into()));
        }
        // Lowest λ first: μ descending. x has xᵀ(K + σM)x = 1, so φ = x/√μ has φᵀMφ = 1.
        let scaled: Vec<(f64, f64)> = mu.iter().rev().map(|&v| (1.0 / v - sigma, 1.0 / v.sqrt())).collect();
        let reversed: Vec<f64> =
            (0..count).rev().flat_map(|j| vectors[j * n..(j + 1) * n].iter().copied()).collect();
        finish(scaled, &reversed, n)
    };
    match driver::cholesky_pivots(n, k.as_slice())? {
        Ok((lo, hi)) if lo > 1e-7 * hi => inverted(0.0),
        // Rigid-body modes (or a nearly singular K): shift, as the other backends do.
        _ => shifted_twice(k.diagonal().amax() / m.diagonal().amax(), inverted),
    }
}

/// Eigenpairs `first..first + count` (ascending) of A x = λ B x by the chosen driver.
fn pairs(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    first: usize,
    count: usize,
    n: usize,
    method: Method,
) -> Result<(Vec<f64>, Vec<f64>), SolveError> {
    match method {
        Method::Subset => driver::sygvx(n, a.as_slice(), b.as_slice(), first, count),
        Method::All | Method::Auto => {
            let (w, z) = driver::sygvd(n, a.as_slice(), b.as_slice())?;
            Ok((w[first..first + count].to_vec(), z[first * n..(first + count) * n].to_vec()))
        }
    }
}

/// Modes from (λ, column scale) pairs and the columns (n each), sorted ascending by λ, with the
/// sign rule; non-finite results are an error.
fn finish(pairs: Vec<(f64, f64)>, vectors: &[f64], n: usize) -> Result<Modes, SolveError> {
    let count = pairs.len();
    if pairs.iter().any(|(l, s)| !l.is_finite() || !s.is_finite()) || vectors.iter().any(|v| !v.is_finite()) {
        return Err(backend("non-finite result (overflow?)".into()));
    }
    // The drivers return ascending eigenvalues; sort anyway so the contract never rests on it.
    let mut order: Vec<usize> = (0..count).collect();
    order.sort_by(|&i, &j| pairs[i].0.total_cmp(&pairs[j].0));
    let eigenvalues = DVector::from_iterator(count, order.iter().map(|&i| pairs[i].0));
    let mut shapes = DMatrix::from_iterator(
        n,
        count,
        order.iter().flat_map(|&j| {
            let scale = pairs[j].1;
            vectors[j * n..(j + 1) * n].iter().map(move |v| v * scale)
        }),
    );
    apply_sign_rule(&mut shapes);
    Ok(Modes { eigenvalues, shapes })
}

fn backend(detail: String) -> SolveError {
    SolveError::Backend { backend: BACKEND, detail }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_input_is_an_error_on_both_paths() {
        let k = DMatrix::from_row_slice(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]);
        let m = DMatrix::identity(2, 2);
        for method in [Method::All, Method::Subset] {
            assert!(matches!(solve(&k, &m, 1, method), Err(SolveError::Backend { backend: "lapack", .. })));
            assert!(matches!(solve(&m, &k, 1, method), Err(SolveError::Backend { .. })));
        }
    }

    #[test]
    fn overflowing_eigenvalues_are_an_error_not_a_panic() {
        let k = DMatrix::from_diagonal_element(3, 3, 1e300);
        let m = DMatrix::from_diagonal_element(3, 3, 1e-300);
        for method in [Method::All, Method::Subset] {
            let sys = System::new(k.clone(), m.clone()).unwrap();
            let r = LapackSolver::new(method).lowest(&sys, 2);
            assert!(matches!(r, Err(SolveError::Backend { .. })), "{method:?}: {r:?}");
        }
    }

    #[test]
    fn single_dof_on_both_paths() {
        let sys = System::new(DMatrix::from_element(1, 1, 4.0), DMatrix::from_element(1, 1, 2.0)).unwrap();
        for method in [Method::All, Method::Subset] {
            let modes = LapackSolver::new(method).lowest(&sys, 1).unwrap();
            assert!((modes.eigenvalues[0] - 2.0).abs() < 1e-15);
            assert!((modes.shapes[(0, 0)] - 0.5_f64.sqrt()).abs() < 1e-15);
        }
    }

    #[test]
    fn auto_resolves_by_fraction_of_modes() {
        assert_eq!(Method::Auto.resolve(2, 1), Method::All);
        assert_eq!(Method::Auto.resolve(5, 1), Method::Subset);
        assert_eq!(Method::Auto.resolve(8, 2), Method::All);
        assert_eq!(Method::Auto.resolve(9, 2), Method::Subset);
        assert_eq!(Method::Subset.resolve(2, 2), Method::Subset);
        assert_eq!(LapackSolver::default().name(), "lapack");
    }
}
