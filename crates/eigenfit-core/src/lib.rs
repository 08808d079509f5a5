//! # eigenfit-core
//!
//! The generic half of eigenfit: what a structure is ([`StructuralModel`](model::StructuralModel)),
//! how its modes are computed ([`EigenSolver`](eigen::EigenSolver), with the pure-nalgebra
//! [`DenseSolver`](eigen::DenseSolver) as default), how the modes move when a parameter moves
//! ([`sensitivity`]), and how parameters are estimated from measured modes.
//!
//! The modules are layers, each using only those listed before it (the `layering` test checks
//! this): [`units`] → [`matrix`] → [`model`] → [`eigen`] → [`sensitivity`] → [`measurement`] →
//! [`problem`] → [`update`] → [`analysis`] → [`discovery`]. Every item has one path, in its
//! layer; [`prelude`] gathers the ones most programs need. [`nalgebra`] is re-exported so callers
//! use the matching version.
//!
//! Conventions: SI units inside, eigenvalues λ = ω² in (rad/s)², ascending; mode shapes are
//! mass-normalised (ΦᵀMΦ = I) with the sign rule of [`apply_sign_rule`](eigen::apply_sign_rule).
//!
//! ```
//! use eigenfit_core::nalgebra::DMatrix;
//! use eigenfit_core::prelude::*;
//!
//! // Two masses on springs: K = [[2,-1],[-1,2]], M = I  →  λ = 1, 3.
//! let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 2.0]);
//! let m = DMatrix::identity(2, 2);
//! let modes = DenseSolver::default().lowest(&System::new(k, m)?, 2)?;
//! assert!((modes.eigenvalues[0] - 1.0).abs() < 1e-12);
//! assert!((modes.eigenvalues[1] - 3.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod units;
// Finite-difference references for plugins' derivative tests (uses nothing of core).
pub mod testing;
// "No such name" messages with the valid names and the nearest (uses nothing of core).
pub mod names;

pub mod matrix;

pub mod model;

pub mod eigen;

pub mod sensitivity;

pub mod measurement;

pub mod problem;

pub mod update;

pub mod analysis;

pub mod discovery;

pub mod prelude;

#[cfg(test)]
mod test_chain;

pub use nalgebra;
