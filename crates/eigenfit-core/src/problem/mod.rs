//! Problem layer: a model, a solver and a measurement make a [`Problem`]; its residual, mode
//! [`Pairing`] and [`Linearisation`] (residual and Jacobian at a point); the
//! [`Objective`] every update strategy works on; and [`multi`] for several
//! configurations stacked into one objective.
//!
//! Depends on [`measurement`](crate::measurement), [`sensitivity`](crate::sensitivity) and below.

pub mod multi;
pub(crate) mod objective;
pub(crate) mod residual;

pub use objective::Objective;
pub use residual::{EigenView, Linearisation, Pairing, Problem, ResidualError, ResidualKind};
