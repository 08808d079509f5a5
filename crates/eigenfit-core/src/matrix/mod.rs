//! Matrix layer: the stiffness–mass pair [`System`] and its storage — dense, [`SparseSymmetric`]
//! (triplets), [`BandedSymmetric`] with its [`BandCholesky`] factor, and [`CscSymmetric`]; the
//! [`Expansion`] T of a static condensation, through which condensed derivatives are applied, and
//! the [`Condensed`] system kept as its full sparse pencil.
//!
//! Depends only on [`units`](crate::units). Files are named after their main type.

pub(crate) mod banded;
pub(crate) mod condensed;
pub(crate) mod csc;
pub(crate) mod expansion;
pub(crate) mod sparse;
pub(crate) mod sparse_cholesky;
pub(crate) mod system;

pub use banded::{BandCholesky, BandedSymmetric};
pub use condensed::Condensed;
pub use csc::CscSymmetric;
pub use expansion::Expansion;
pub use sparse::SparseSymmetric;
pub use system::{System, SystemDerivative, SystemError, MAX_BAND_ENTRIES_FOR_PIVOT};
