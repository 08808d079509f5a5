//! # eigenfit
//!
//! Finite-element model updating by eigenvalue sensitivity. This facade re-exports the pieces:
//! [`core`] (traits, dense solver, sensitivities), [`rotor`] (the rotor plugin) and, with the
//! `lapack` feature, [`lapack`] (the LAPACK eigen-solver backend).

pub use eigenfit_core as core;
pub use eigenfit_core::*;
#[cfg(feature = "lapack")]
pub use eigenfit_lapack as lapack;
pub use eigenfit_rotor as rotor;
/// Whole jobs (simulate, estimate, compare, discover, campbell, campaign) with serde reports.
pub use eigenfit_workflow as workflow;
