//! # eigenfit
//!
//! Finite-element model updating by eigenvalue sensitivity. This facade re-exports the crates
//! as modules — [`core`] (models, eigen-solvers, sensitivities, estimation, in layers),
//! [`rotor`] (the planar rotor plugin), and behind features (on by default): `matrices` (models
//! from any FE tool's matrices), `rotordynamics` (two-plane rotors at speed, ROSS files) and
//! `workflow` (the jobs as library calls); with the `lapack` feature, `lapack` (the LAPACK
//! eigen-solver backend) — plus a [`prelude`] and the matching [`nalgebra`].
//! `default-features = false` is the lean library: core and the planar rotor.
//!
//! ```
//! use eigenfit::nalgebra::DMatrix;
//! use eigenfit::prelude::*;
//!
//! let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 2.0]);
//! let modes = DenseSolver::default().lowest(&System::new(k, DMatrix::identity(2, 2))?, 2)?;
//! assert!((modes.eigenvalues[1] - 3.0).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use eigenfit_core as core;
pub use eigenfit_core::nalgebra;
#[cfg(feature = "lapack")]
pub use eigenfit_lapack as lapack;
#[cfg(feature = "matrices")]
pub use eigenfit_matrices as matrices;
pub use eigenfit_rotor as rotor;
#[cfg(feature = "rotordynamics")]
pub use eigenfit_rotordynamics as rotordynamics;
/// Whole jobs (simulate, estimate, compare, discover, campbell, campaign, bench) with serde reports.
#[cfg(feature = "workflow")]
pub use eigenfit_workflow as workflow;

/// The items most programs need: the core prelude and the rotor model.
pub mod prelude {
    pub use eigenfit_core::prelude::*;
    pub use eigenfit_rotor::Rotor;
}
