//! The [`EigenSolver`] trait for the generalized symmetric-definite problem K φ = λ M φ.

use crate::eigen::Modes;
use crate::matrix::System;
use nalgebra::DVector;
use thiserror::Error;

/// Why an eigen-solve failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SolveError {
    /// M is not positive definite (a massless DOF, a negative mass, …).
    #[error("the mass matrix is not positive definite{}", .detail.as_deref().map(|d| format!(" ({d})")).unwrap_or_default())]
    MassNotPositiveDefinite { detail: Option<String> },
    /// More modes were requested than the system has.
    #[error("{requested} modes requested but the system has only {available} degrees of freedom")]
    TooManyModes { requested: usize, available: usize },
    /// Zero modes were requested.
    #[error("at least one mode must be requested")]
    NoModes,
    /// The backend produced NaN or did not converge.
    #[error("eigen-solver `{backend}` failed: {detail}")]
    Backend { backend: &'static str, detail: String },
}

/// Computes the lowest modes of K φ = λ M φ.
///
/// Implementations return λ ascending and Φ mass-normalised (ΦᵀMΦ = I) with
/// [`apply_sign_rule`](crate::eigen::apply_sign_rule) applied, so backends are interchangeable.
///
/// Solvers are `Send + Sync` so batches ([`compare::run_grid`](crate::analysis::compare::run_grid)) can
/// share one across threads.
pub trait EigenSolver: Send + Sync {
    /// Short backend name for reports, e.g. `dense` or `lapack`.
    fn name(&self) -> &'static str;

    /// The lowest `count` modes.
    fn lowest(&self, system: &System, count: usize) -> Result<Modes, SolveError>;

    /// The lowest `count` eigenvalues only, as [`lowest`](Self::lowest) computes them to round-off;
    /// backends may skip the shapes, or iterate them less far when the eigenvalues are Rayleigh
    /// quotients (error: the square of the shapes') — used to rank many candidate points by cost.
    fn lowest_eigenvalues(&self, system: &System, count: usize) -> Result<DVector<f64>, SolveError> {
        self.lowest(system, count).map(|m| m.eigenvalues)
    }

    /// The lowest `count` modes and a lower bound on the next eigenvalue λ_count (∞ when the
    /// system has no further mode), to check that the highest mode returned is separated from
    /// its neighbour. The default solves one mode more and returns that eigenvalue itself; a
    /// backend with a cheaper certificate (the banded solver's Sturm count) returns a bound.
    fn lowest_with_next(&self, system: &System, count: usize) -> Result<(Modes, f64), SolveError> {
        if count >= system.dofs() {
            return self.lowest(system, count).map(|m| (m, f64::INFINITY));
        }
        let modes = self.lowest(system, count + 1)?;
        let next = modes.eigenvalues[count];
        let modes = Modes {
            eigenvalues: modes.eigenvalues.rows(0, count).into_owned(),
            shapes: modes.shapes.columns(0, count).into_owned(),
        };
        Ok((modes, next))
    }

    /// [`lowest_with_next`](Self::lowest_with_next) without the shapes (backends may skip them).
    fn lowest_eigenvalues_with_next(
        &self,
        system: &System,
        count: usize,
    ) -> Result<(DVector<f64>, f64), SolveError> {
        if count >= system.dofs() {
            return self.lowest_eigenvalues(system, count).map(|e| (e, f64::INFINITY));
        }
        let all = self.lowest_eigenvalues(system, count + 1)?;
        Ok((all.rows(0, count).into_owned(), all[count]))
    }
}

impl<T: EigenSolver + ?Sized> EigenSolver for &T {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn lowest(&self, system: &System, count: usize) -> Result<Modes, SolveError> {
        (**self).lowest(system, count)
    }
    fn lowest_eigenvalues(&self, system: &System, count: usize) -> Result<DVector<f64>, SolveError> {
        (**self).lowest_eigenvalues(system, count)
    }
    fn lowest_with_next(&self, system: &System, count: usize) -> Result<(Modes, f64), SolveError> {
        (**self).lowest_with_next(system, count)
    }
    fn lowest_eigenvalues_with_next(
        &self,
        system: &System,
        count: usize,
    ) -> Result<(DVector<f64>, f64), SolveError> {
        (**self).lowest_eigenvalues_with_next(system, count)
    }
}

/// The inverted reduction's shift for a singular or nearly singular K (rigid-body modes), shared
/// by the backends: a first solve with a tiny shift σ₀ = 1e-8·`scale` (`scale` = max Kᵢᵢ / max Mᵢᵢ)
/// locates the lowest elastic mode, and a second shifts to it — a mode's relative error is
/// ε·(λ + σ)²/(σλ), smallest near σ = λ and ε·λ/σ above it. `solve(σ)` returns the lowest modes
/// of K φ = λ M φ computed through K + σM.
pub fn shifted_twice(
    scale: f64,
    mut solve: impl FnMut(f64) -> Result<Modes, SolveError>,
) -> Result<Modes, SolveError> {
    let sigma0 = 1e-8 * scale.max(f64::MIN_POSITIVE);
    let first = solve(sigma0)?;
    match first.eigenvalues.iter().find(|&&l| l > 1e-3 * sigma0) {
        Some(&sigma1) if sigma1 > 10.0 * sigma0 => solve(sigma1),
        _ => Ok(first),
    }
}

/// Checks `count` against the system size; shared by all backends.
pub fn check_count(system: &System, count: usize) -> Result<(), SolveError> {
    if count == 0 {
        return Err(SolveError::NoModes);
    }
    if count > system.dofs() {
        return Err(SolveError::TooManyModes { requested: count, available: system.dofs() });
    }
    Ok(())
}
