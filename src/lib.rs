//! # eigenfit
//!
//! Finite-element model updating by eigenvalue sensitivity. This facade re-exports the crates
//! as modules — [`core`] (models, eigen-solvers, sensitivities, estimation, in layers),
//! [`rotor`] (the rotor plugin) and, with the `lapack` feature, [`lapack`] (the LAPACK
//! eigen-solver backend) — plus a [`prelude`] and the matching [`nalgebra`].
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
pub use eigenfit_rotor as rotor;

/// The items most programs need: the core prelude and the rotor model.
pub mod prelude {
    pub use eigenfit_core::prelude::*;
    pub use eigenfit_rotor::Rotor;
}
