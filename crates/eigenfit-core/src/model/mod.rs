//! Model layer: what a structure is ([`StructuralModel`]), its updatable [`ParameterSet`], a
//! model with some parameters held [`Fixed`], and the [`Candidate`] effects a model can offer to
//! discovery (with the [`Augmented`] model that adds them).
//!
//! Depends on [`matrix`](crate::matrix) and below.

pub(crate) mod augmented;
pub(crate) mod candidate;
pub(crate) mod fixed;
pub(crate) mod parameters;
pub(crate) mod structural_model;
pub mod truss;

pub use augmented::Augmented;
pub use candidate::{Candidate, Companion, GradedPart, ValueLaw};
pub use fixed::Fixed;
pub use parameters::{bracketed, Parameter, ParameterError, ParameterSet, Scale};
pub use structural_model::{finite_difference_derivative, ModelError, StructuralModel};
