//! The [`EigenSolver`] trait for the generalized symmetric-definite problem K φ = λ M φ.

use crate::eigen::Modes;
use crate::matrix::System;
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

/// Why an eigen-solve failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SolveError {
    /// M is not positive definite (a massless DOF, a negative mass, …). `dof` (from 0, in the
    /// system's numbering) is where its Cholesky factorisation fails
    /// ([`System::mass_failure_dof`]), filled by [`SolveError::located`].
    #[error(
        "the mass matrix is not positive definite{}{}",
        .dof.map(|j| format!(" at DOF {} (its Cholesky factorisation fails at that pivot)", j + 1)).unwrap_or_default(),
        .detail.as_deref().map(|d| format!(" ({d})")).unwrap_or_default()
    )]
    MassNotPositiveDefinite { detail: Option<String>, dof: Option<usize> },
    /// More modes were requested than the system has.
    #[error("{requested} modes requested but the system has only {available} degrees of freedom")]
    TooManyModes { requested: usize, available: usize },
    /// Zero modes were requested.
    #[error("at least one mode must be requested")]
    NoModes,
    /// The backend produced NaN or did not converge.
    #[error("eigen-solver `{backend}` failed: {detail}")]
    Backend { backend: &'static str, detail: String },
    /// The iteration did not reach its tolerance within its step limit (closely spaced
    /// eigenvalues at the modes asked for) on valid input: another solver, or fewer modes, may.
    #[error("eigen-solver `{backend}` did not converge: {detail}")]
    NotConverged { backend: &'static str, detail: String },
}

impl SolveError {
    /// The same error with the DOF at which M's factorisation fails filled in (for
    /// [`MassNotPositiveDefinite`](Self::MassNotPositiveDefinite) without one); every solver
    /// passes its errors through this, so the failure names a DOF whatever the backend.
    pub fn located(self, system: &System) -> Self {
        match self {
            Self::MassNotPositiveDefinite { detail, dof: None } => {
                Self::MassNotPositiveDefinite { detail, dof: system.mass_failure_dof() }
            }
            other => other,
        }
    }
}

/// What one eigen-solve is asked for: how many of the lowest modes, whether their shapes are
/// needed, and whether to certify that none was missed.
///
/// ```
/// use eigenfit_core::eigen::ModeRequest;
/// let request = ModeRequest::eigenvalues(3).with_certificate();
/// assert_eq!((request.count, request.vectors, request.certificate), (3, false, true));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModeRequest {
    /// How many of the lowest modes.
    pub count: usize,
    /// Whether the mode shapes are wanted; when `false` the backend may skip them, or iterate
    /// them less far when its eigenvalues are Rayleigh quotients (error: the square of the
    /// shapes'), and [`Modes::shapes`] comes back with no columns.
    pub vectors: bool,
    /// Whether to return [`SolvedModes::next_eigenvalue`]: a lower bound on the eigenvalue after
    /// the highest one returned, proving that the modes returned are the lowest and that the
    /// highest is separated from its neighbour.
    pub certificate: bool,
}

impl ModeRequest {
    /// The lowest `count` modes with their shapes, no certificate.
    pub const fn modes(count: usize) -> Self {
        Self { count, vectors: true, certificate: false }
    }

    /// The lowest `count` eigenvalues only.
    pub const fn eigenvalues(count: usize) -> Self {
        Self { count, vectors: false, certificate: false }
    }

    /// The same request with the next-eigenvalue certificate.
    pub const fn with_certificate(self) -> Self {
        Self { certificate: true, ..self }
    }
}

/// What [`EigenSolver::solve`] returns for a [`ModeRequest`].
#[derive(Debug, Clone, PartialEq)]
pub struct SolvedModes {
    /// The lowest modes; `shapes` has no columns when the request asked for eigenvalues only.
    pub modes: Modes,
    /// With [`ModeRequest::certificate`]: a lower bound on the next eigenvalue λ_count (∞ when
    /// the system has no further mode); `None` when no certificate was asked for.
    pub next_eigenvalue: Option<f64>,
}

/// Computes the lowest modes of K φ = λ M φ.
///
/// Implementations return λ ascending and Φ mass-normalised (ΦᵀMΦ = I) with
/// [`apply_sign_rule`](crate::eigen::apply_sign_rule) applied, so backends are interchangeable.
/// A backend implements [`solve`](Self::solve) only; the `lowest*` methods are shorthands for
/// the common requests.
///
/// Solvers are `Send + Sync` so batches ([`compare::run_grid`](crate::analysis::compare::run_grid)) can
/// share one across threads.
pub trait EigenSolver: Send + Sync {
    /// Short backend name for reports, e.g. `dense` or `lapack`.
    fn name(&self) -> &'static str;

    /// The modes `request` asks for. Eigenvalues only (`vectors: false`) agree with a full
    /// solve's to the backend's tolerance. A backend without a cheaper certificate solves one
    /// mode more ([`with_next_by_one_more_mode`]); the banded and sparse solvers return their
    /// Sturm count's shift, a bound found at no extra cost.
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError>;

    /// The lowest `count` modes.
    fn lowest(&self, system: &System, count: usize) -> Result<Modes, SolveError> {
        self.solve(system, ModeRequest::modes(count)).map(|s| s.modes)
    }

    /// The lowest `count` eigenvalues only (see [`ModeRequest::vectors`]) — used to rank many
    /// candidate points by cost.
    fn lowest_eigenvalues(&self, system: &System, count: usize) -> Result<DVector<f64>, SolveError> {
        self.solve(system, ModeRequest::eigenvalues(count)).map(|s| s.modes.eigenvalues)
    }

    /// The lowest `count` modes and a lower bound on the next eigenvalue λ_count (∞ when the
    /// system has no further mode), to check that the highest mode returned is separated from
    /// its neighbour.
    fn lowest_with_next(&self, system: &System, count: usize) -> Result<(Modes, f64), SolveError> {
        certified(self.name(), self.solve(system, ModeRequest::modes(count).with_certificate())?)
    }

    /// [`lowest_with_next`](Self::lowest_with_next) without the shapes.
    fn lowest_eigenvalues_with_next(
        &self,
        system: &System,
        count: usize,
    ) -> Result<(DVector<f64>, f64), SolveError> {
        certified(self.name(), self.solve(system, ModeRequest::eigenvalues(count).with_certificate())?)
            .map(|(modes, next)| (modes.eigenvalues, next))
    }
}

impl<T: EigenSolver + ?Sized> EigenSolver for &T {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn solve(&self, system: &System, request: ModeRequest) -> Result<SolvedModes, SolveError> {
        (**self).solve(system, request)
    }
}

/// The modes and the certificate a backend was asked for; its absence is the backend's fault.
fn certified(backend: &'static str, solved: SolvedModes) -> Result<(Modes, f64), SolveError> {
    match solved.next_eigenvalue {
        Some(next) => Ok((solved.modes, next)),
        None => {
            Err(SolveError::Backend { backend, detail: "no next-eigenvalue certificate returned".into() })
        }
    }
}

/// [`EigenSolver::solve`] for a backend whose only certificate is the next eigenvalue itself:
/// `solve` computes the lowest `count` modes (shapes when `vectors`), and a certified request
/// asks it for one mode more, whose eigenvalue is returned as the bound (∞ when the system has
/// no further mode). Shapes are dropped when the request did not ask for them.
pub fn with_next_by_one_more_mode(
    system: &System,
    request: ModeRequest,
    mut solve: impl FnMut(usize, bool) -> Result<Modes, SolveError>,
) -> Result<SolvedModes, SolveError> {
    let ModeRequest { count, vectors, certificate } = request;
    if !certificate {
        return solve(count, vectors)
            .map(|modes| SolvedModes { modes: drop_shapes(modes, vectors), next_eigenvalue: None });
    }
    if count >= system.dofs() {
        let modes = solve(count, vectors)?;
        return Ok(SolvedModes { modes: drop_shapes(modes, vectors), next_eigenvalue: Some(f64::INFINITY) });
    }
    let more = solve(count + 1, vectors)?;
    let next = more.eigenvalues[count];
    let shapes =
        if vectors { more.shapes.columns(0, count).into_owned() } else { no_shapes(more.shapes.nrows()) };
    let modes = Modes { eigenvalues: more.eigenvalues.rows(0, count).into_owned(), shapes };
    Ok(SolvedModes { modes, next_eigenvalue: Some(next) })
}

impl SolvedModes {
    /// What `request` asked for from `modes` and a backend's bound `next` on the next eigenvalue.
    pub fn answering(request: ModeRequest, modes: Modes, next: f64) -> Self {
        Self {
            modes: drop_shapes(modes, request.vectors),
            next_eigenvalue: request.certificate.then_some(next),
        }
    }
}

/// The convergence tolerance of an iterative backend for `request`: `tolerance` with shapes; for
/// eigenvalues only, √tolerance / 10 (when larger), since Rayleigh-quotient eigenvalues are
/// accurate to the square of the vectors' error.
pub(crate) fn request_tolerance(request: ModeRequest, tolerance: f64) -> f64 {
    if request.vectors {
        tolerance
    } else {
        tolerance.max(0.1 * tolerance.sqrt())
    }
}

/// `modes` as a request for `vectors` wants them: without shape columns when it asked for
/// eigenvalues only.
pub fn drop_shapes(modes: Modes, vectors: bool) -> Modes {
    if vectors {
        modes
    } else {
        Modes { shapes: no_shapes(modes.shapes.nrows()), eigenvalues: modes.eigenvalues }
    }
}

/// An n×0 shape matrix: eigenvalues only.
fn no_shapes(n: usize) -> DMatrix<f64> {
    DMatrix::zeros(n, 0)
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
