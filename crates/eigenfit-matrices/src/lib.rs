//! # eigenfit-matrices
//!
//! Models from any finite-element tool: stiffness and mass matrices exported as Matrix Market
//! files (Abaqus, ANSYS, Nastran, ROSS's `Rotor.save_mat`, scipy), updated by substructure
//! parameters as commercial updating tools do,
//!
//! K(p) = K₀ + Σ pᵢ Kᵢ,  M(p) = M₀ + Σ pᵢ Mᵢ.
//!
//! A model file (TOML, paths relative to it; see docs/matrices.md):
//!
//! ```toml
//! kind = "matrices"
//! stiffness = "K0.mtx"
//! mass = "M0.mtx"
//! [[parameter]]
//! name = "zone1"
//! nominal = 1.0
//! lower = 0.01
//! upper = 100.0
//! scale = "log"
//! stiffness = "K1.mtx"
//! ```
//!
//! [`MatricesModel`] implements [`StructuralModel`](eigenfit_core::model::StructuralModel); its systems
//! are stored sparse, for [`SparseSolver`](eigenfit_core::eigen::SparseSolver).

mod error;
mod layout;
pub mod market;
mod model;
mod symmetry;

pub use error::MatricesError;
pub use layout::{Dof, DofLayout};
pub use model::MatricesModel;

/// Whether the TOML text declares `kind = "matrices"` (cheap, for routing a `--model` file).
pub fn is_matrices_file(text: &str) -> bool {
    toml::from_str::<toml::Table>(text)
        .ok()
        .and_then(|t| t.get("kind").and_then(|k| k.as_str().map(|s| s == "matrices")))
        .unwrap_or(false)
}
