//! The items most programs need, for `use eigenfit_core::prelude::*;`: build a model, solve it,
//! set up a problem from measured modes, run a strategy, read the estimate and its intervals.
//! Each item keeps its one path in its layer; this is only a shortcut to them.

pub use crate::analysis::{uncertainty, Uncertainty};
pub use crate::eigen::{BandedSolver, DenseSolver, EigenSolver, Modes, SolveError, SparseSolver};
pub use crate::matrix::{SparseSymmetric, System, SystemDerivative};
pub use crate::measurement::{MeasuredMode, Measurement};
pub use crate::model::{ModelError, Parameter, ParameterSet, Scale, StructuralModel};
pub use crate::problem::{Linearisation, Objective, Pairing, Problem};
pub use crate::units::{eigenvalue_to_hz, hz_to_eigenvalue};
pub use crate::update::{Driver, Estimate, LevenbergMarquardt, Newton, PStep, Termination, UpdateStrategy};
