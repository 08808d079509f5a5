//! # eigenfit-core
//!
//! The generic half of eigenfit: what a structure is ([`StructuralModel`]), how its modes are
//! computed ([`EigenSolver`], with the pure-nalgebra [`DenseSolver`] as default), and how the
//! modes move when a parameter moves ([`sensitivity`]).
//!
//! Conventions: SI units inside, eigenvalues λ = ω² in (rad/s)², ascending; mode shapes are
//! mass-normalised (ΦᵀMΦ = I) with the sign rule of [`apply_sign_rule`].
//!
//! ```
//! use eigenfit_core::{DenseSolver, EigenSolver, System};
//! use nalgebra::DMatrix;
//!
//! // Two masses on springs: K = [[2,-1],[-1,2]], M = I  →  λ = 1, 3.
//! let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 2.0]);
//! let m = DMatrix::identity(2, 2);
//! let modes = DenseSolver::default().lowest(&System::new(k, m)?, 2)?;
//! assert!((modes.eigenvalues[0] - 1.0).abs() < 1e-12);
//! assert!((modes.eigenvalues[1] - 3.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod banded;
pub mod compare;
pub mod csc;
pub mod dense;
pub mod discovery;
pub mod fixed;
mod lanczos;
pub mod measurement;
pub mod model;
pub mod modes;
pub mod monte_carlo;
pub mod multi;
pub mod parameters;
pub mod residual;
pub mod roundoff;
pub mod sensitivity;
mod small_eigen;
pub mod solver;
pub mod sparse;
pub mod sparse_solver;
pub mod statistics;
pub mod subspace;
pub mod synthetic;
pub mod system;
#[cfg(test)]
mod test_chain;
pub mod testdata;
pub mod update;
pub mod verdict;

pub use banded::{BandCholesky, BandedSymmetric};
pub use csc::CscSymmetric;
pub use dense::DenseSolver;
pub use measurement::{MeasuredMode, Measurement, MeasurementError};
pub use model::{finite_difference_derivative, ModelError, StructuralModel};
pub use modes::{apply_sign_rule, Modes};
pub use parameters::{Parameter, ParameterError, ParameterSet, Scale};
pub use residual::{Linearisation, Pairing, Problem, ResidualError, ResidualKind};
pub use sensitivity::{Sensitivities, SensitivityError};
pub use solver::{EigenSolver, SolveError};
pub use sparse::SparseSymmetric;
pub use sparse_solver::SparseSolver;
pub use statistics::{
    alternative_solutions, alternative_solutions_within, mirror_solutions, uncertainty, uncertainty_within,
    Identifiability, Uncertainty,
};
pub use subspace::BandedSolver;
pub use system::{System, SystemDerivative, SystemError};
pub use update::{
    Budget, Damped, Driver, Estimate, Evaluate, IterationRecord, IterationRecordSink, Newton, Observer,
    PStep, Step, StepStatus, StrategyKind, Termination, UpdateError, UpdateStrategy,
};

/// Converts an eigenvalue λ = ω² (rad/s)² to a frequency in Hz.
///
/// Negative round-off values (rigid-body modes) map to 0 Hz.
pub fn eigenvalue_to_hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// Converts a frequency in Hz to an eigenvalue λ = (2πf)² (the paper's eq. 23).
pub fn hz_to_eigenvalue(f_hz: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f_hz;
    w * w
}
